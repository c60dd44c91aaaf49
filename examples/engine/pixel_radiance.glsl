// The engine examples' shading, shared by the OpenGL ES fragment shader
// (engine_example.cpp) and the Vulkan compute shader (vulkan_example.cpp):
// one ray per pixel, sky (with the sun's disc) where it misses the ground,
// lit ground seen through the atmosphere where it hits it. The pixel-to-ray
// mappings and the shading are those of render/views.cpp.
//
// Include after the runtime snippet. The including shader declares the four
// tables (transmittance_texture, scattering_texture,
// single_mie_scattering_texture, irradiance_texture) and the view's values:
//   int view;             0: fisheye, 1: aerial
//   vec2 image_size;
//   float camera_altitude;
//   vec3 sun_direction;
//   vec3 forward, right, camera_up;   the aerial camera's basis
//   vec3 ground_albedo;
//   float cos_disc;       the drawn sun disc: at least one pixel wide,
//   float disc_scale;     its radiance scaled to keep the sun's irradiance
//
// A scene's bake (examples/scenes/README.md) ships a pruned snippet:
// atmosphere_constants.glsl sets SKYBAKE_HAS_SCATTERING_TEXTURE,
// SKYBAKE_HAS_IRRADIANCE_TEXTURE and SKYBAKE_HAS_AERIAL_PERSPECTIVE, and
// functions.glsl compiles only the functions whose tables exist, so the
// shading calls a function only under its macro and draws what the set holds:
//   no scattering table:  a black sky (the sun's disc still dims through the
//                         air by the transmittance table);
//   no aerial perspective: the ground unveiled (no in-scattering, no
//                         extinction between it and the camera);
//   no irradiance table:  the ground lit by the direct sun only (as
//                         GetSunAndSkyIrradiance computes it, without the sky
//                         term), as an engine that lights it by its own
//                         probes would have them add the rest.

vec3 Sky(vec3 camera, vec3 dir, out vec3 transmittance) {
#if SKYBAKE_HAS_SCATTERING_TEXTURE
  return GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                        camera, dir, sun_direction, transmittance);
#else
  float r = ClampRadius(ATMOSPHERE, length(camera));
  transmittance = GetTransmittanceToTopAtmosphereBoundary(ATMOSPHERE, transmittance_texture, r,
                                                          ClampCosine(dot(camera, dir) / length(camera)));
  return vec3(0.0);
#endif
}

vec3 GroundLight(vec3 point, vec3 normal) {
#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
  vec3 sky_irradiance;
  vec3 sun_irradiance = GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, point, normal,
                                               sun_direction, sky_irradiance);
  return sun_irradiance + sky_irradiance;
#else
  float r = ClampRadius(ATMOSPHERE, length(point));
  float mu_s = ClampCosine(dot(point, sun_direction) / length(point));
  return ATMOSPHERE.solar_irradiance * GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, r, mu_s) *
         max(dot(normal, sun_direction), 0.0);
#endif
}

vec3 AerialPerspective(vec3 camera, vec3 point, out vec3 transmittance) {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
  return GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                               camera, point, sun_direction, transmittance);
#else
  transmittance = vec3(1.0);
  return vec3(0.0);
#endif
}

// The radiance of the pixel whose centre is `p`, measured from the image's
// top-left corner.
vec3 PixelRadiance(vec2 p) {
  vec3 dir;
  if (view == 0) {
    vec2 d = (image_size.x / 2.0 - p) / (image_size.x / 2.0);
    float rho = length(d);
    if (rho > 1.0) return vec3(0.0);
    float theta = rho * PI / 2.0;
    float phi = atan(d.y, d.x);
    dir = vec3(sin(theta) * cos(phi), sin(theta) * sin(phi), cos(theta));
  } else {
    float u = 2.0 * p.x / image_size.x - 1.0;
    float v = (1.0 - 2.0 * p.y / image_size.y) * (image_size.y / image_size.x);
    dir = normalize(forward + right * u + camera_up * v);
  }
  float bottom = ATMOSPHERE.bottom_radius;
  vec3 camera = vec3(0.0, 0.0, bottom + camera_altitude);
  // Distance to the ground, in the form without cancellation: products of
  // radii near 6.4e6 m would lose everything in float.
  float b = camera.z * dir.z;
  float c = camera_altitude * (2.0 * bottom + camera_altitude);
  float disc = b * b - c;
  vec3 radiance;
  if (b < 0.0 && disc >= 0.0) {
    float t = c / (sqrt(disc) - b);
    vec3 normal = normalize(camera + dir * t);
    vec3 point = normal * bottom;
    vec3 transmittance;
    vec3 inscatter = AerialPerspective(camera, point, transmittance);
    radiance = ground_albedo / PI * GroundLight(point, normal) * transmittance + inscatter;
  } else {
    vec3 transmittance;
    radiance = Sky(camera, dir, transmittance);
    if (dot(dir, sun_direction) > cos_disc) radiance += GetSolarRadiance(ATMOSPHERE) * transmittance * disc_scale;
  }
  return radiance;
}
