// ---------------------------------------------------------------------------
// Per-frame tables: the sky and the aerial perspective as engines draw them,
// from two small tables that the engine rebuilds each frame with the lookups
// above (one texel per call), then reads with one or two fetches per pixel.
// They hold what GetSkyRadiance and GetSkyRadianceToPoint return for one
// camera and one sun, so the camera and the sun are those of the frame.

#if SKYBAKE_HAS_SCATTERING_TEXTURE
// The sky view, SKY_VIEW_WIDTH x SKY_VIEW_HEIGHT texels (2D, RGBA16F or
// RGBA32F, linear filtering, clamp to edge): GetSkyRadiance from the camera
// in every direction. x is the azimuth phi from the sun's, evenly from 0 to
// pi (the sky is symmetric about the sun's vertical plane). y is the view
// zenith angle theta, split at the horizon's theta_h as the scattering
// table's mu axis is: rays that hit the ground in the lower half, the others
// in the upper half, the horizon at the outer edges and the nadir and the
// zenith next to the middle. Within a half the unit x (GetTextureCoordFromUnitMuInHalf)
// is 1 - sqrt(e / e_max), e the angle from the horizon and e_max its
// largest (theta_h up, pi - theta_h down): rows crowd toward the horizon,
// where the light changes fastest, and each half is sampled between its own
// texel centres, so that the filter never blends the ground with the sky.
// The angles come from atan, which GPUs approximate far more closely than
// acos (shaders_runtime/README.md, "Precision"). For cameras in the
// atmosphere: from space, rays enter it at radii that differ from ray to
// ray, and GetSkyRadiance is the lookup.
const int SKY_VIEW_WIDTH = 192;
const int SKY_VIEW_HEIGHT = 108;

// The zenith angle of the horizon seen from radius r: its cosine is
// -rho / r, its sine bottom / r.
Number SkyViewHorizonZenith(IN(AtmosphereParameters) atmosphere, Number r) {
  return atan(atmosphere.bottom_radius, -HorizonDistance(atmosphere, r));
}

// The sky view's texture coordinates of the ray at zenith angle theta and
// azimuth phi from the sun, from radius r.
vec2 GetSkyViewUvFromAngles(IN(AtmosphereParameters) atmosphere, Number r, Number theta, Number phi,
                            bool ray_r_mu_intersects_ground) {
  Number theta_h = SkyViewHorizonZenith(atmosphere, r);
  Number x = ray_r_mu_intersects_ground ? 1.0 - sqrt(clamp((theta - theta_h) / (PI - theta_h), 0.0, 1.0))
                                        : 1.0 - sqrt(clamp((theta_h - theta) / theta_h, 0.0, 1.0));
  return vec2(GetTextureCoordFromUnitRange(phi / PI, SKY_VIEW_WIDTH),
              GetTextureCoordFromUnitMuInHalf(x, ray_r_mu_intersects_ground, SKY_VIEW_HEIGHT));
}

// The angles of the sky view of the unit view_ray from `camera`: the zenith
// angle theta from the view's vertical and horizontal parts, and the azimuth
// phi from its and the sun's horizontal parts h and s, atan(|(up x s) . h|, s . h).
void GetSkyViewAngles(IN(vec3) camera, IN(vec3) view_ray, IN(vec3) sun_direction, OUT(Number) theta,
                      OUT(Number) phi) {
  vec3 up = normalize(camera);
  Number mu = dot(up, view_ray);
  vec3 horizontal = view_ray - up * mu;
  vec3 sun_horizontal = sun_direction - up * dot(up, sun_direction);
  theta = atan(length(horizontal), mu);
  Number along = dot(sun_horizontal, horizontal);
  Number side = abs(dot(cross(up, sun_horizontal), horizontal));
  phi = along != 0.0 || side != 0.0 ? atan(side, along) : 0.0;
}

// The view direction of the sky view's texel at uv (its centre, as a pass
// over the table gives it: gl_FragCoord.xy / size) for the camera and the
// sun of the frame, and the half of the table it lies in. Its horizontal
// axes: toward the sun's azimuth (any, with the sun at the zenith or the
// nadir), and across it.
vec3 GetSkyViewRay(IN(AtmosphereParameters) atmosphere, IN(vec3) camera, IN(vec3) sun_direction, IN(vec2) uv,
                   OUT(bool) ray_r_mu_intersects_ground) {
  Number x = GetUnitMuInHalfFromTextureCoord(uv.y, SKY_VIEW_HEIGHT, ray_r_mu_intersects_ground);
  Number e = (1.0 - x) * (1.0 - x);
  Number theta_h = SkyViewHorizonZenith(atmosphere, ClampRadius(atmosphere, length(camera)));
  Number theta = ray_r_mu_intersects_ground ? theta_h + e * (PI - theta_h) : theta_h * (1.0 - e);
  Number phi = PI * clamp(GetUnitRangeFromTextureCoord(uv.x, SKY_VIEW_WIDTH), 0.0, 1.0);
  vec3 up = normalize(camera);
  vec3 toward_sun = sun_direction - up * dot(sun_direction, up);
  if (dot(toward_sun, toward_sun) < 1e-12) {
    toward_sun = cross(up, abs(up.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0));
  }
  toward_sun = normalize(toward_sun);
  vec3 across = cross(up, toward_sun);
  return up * cos(theta) + (toward_sun * cos(phi) + across * sin(phi)) * sin(theta);
}

// The sky view's texel at uv: the sky radiance along GetSkyViewRay, on the
// side of the horizon its half stands for (the outer rows lie on the
// horizon itself).
vec3 GetSkyViewRadiance(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                        IN(ScatteringTexture) single_mie_scattering_texture, IN(vec3) camera,
                        IN(vec3) sun_direction, IN(vec2) uv) {
  bool ray_r_mu_intersects_ground;
  vec3 view_ray = GetSkyViewRay(atmosphere, camera, sun_direction, uv, ray_r_mu_intersects_ground);
  vec3 up = normalize(camera);
  return GetSkyRadianceOfRay(atmosphere, scattering_texture, single_mie_scattering_texture,
                             ClampRadius(atmosphere, length(camera)), ClampCosine(dot(up, view_ray)),
                             ClampCosine(dot(up, sun_direction)), ClampCosine(dot(view_ray, sun_direction)),
                             ray_r_mu_intersects_ground);
}

// GetSkyRadiance read from the frame's sky view (one fetch) and the
// transmittance to space from the transmittance table (one fetch; 0 for a
// ray that hits the ground), for the frame's camera and sun.
vec3 GetSkyRadianceFromSkyView(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                               IN(SkyViewTexture) sky_view_texture, IN(vec3) camera, IN(vec3) view_ray,
                               IN(vec3) sun_direction, OUT(vec3) transmittance) {
  Number r = ClampRadius(atmosphere, length(camera));
  Number mu = ClampCosine(dot(camera, view_ray) / length(camera));
  bool ray_r_mu_intersects_ground = RayIntersectsGround(atmosphere, r, mu);
  transmittance = ray_r_mu_intersects_ground
      ? vec3(0.0)
      : GetTransmittanceToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, mu);
  Number theta;
  Number phi;
  GetSkyViewAngles(camera, view_ray, sun_direction, theta, phi);
  return vec3(SampleTexture2D(sky_view_texture,
                              GetSkyViewUvFromAngles(atmosphere, r, theta, phi, ray_r_mu_intersects_ground)));
}
#endif

#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
// The aerial-perspective volume: froxels over the engine's view frustum, x
// and y in screen space (the engine's choice of size, 32 x 32 is usual),
// AERIAL_PERSPECTIVE_SLICES along the distance from the camera. Two 3D
// tables (linear filtering, clamp to edge): the radiance GetSkyRadianceToPoint
// returns, and the optical depth (-ln of its transmittance: it adds along
// the ray, so the lookup scales it, and it varies more evenly than the
// transmittance). Slice k (from 0) holds the points at distance
// D_max ((k + 1) / N)^2 along each froxel's ray (N slices, D_max =
// AERIAL_PERSPECTIVE_MAX_DISTANCE), dense near the camera; points farther
// than D_max read the last slice.
const int AERIAL_PERSPECTIVE_SLICES = 32;
const Number AERIAL_PERSPECTIVE_MAX_DISTANCE = 50000.0;  // metres

// The distance held by slice k.
Number AerialPerspectiveSliceDistance(Number k) {
  Number x = (k + 1.0) / Number(AERIAL_PERSPECTIVE_SLICES);
  return AERIAL_PERSPECTIVE_MAX_DISTANCE * x * x;
}

// The volume's texel at slice coordinate w (its centre, (k + 0.5) / N) along
// the froxel's unit view_ray: the radiance to the point at the slice's
// distance, and its optical depth. A point under the ground is lifted to the
// ground above it, so that a froxel whose ray meets the ground still holds
// points at about its slice's distance (between the froxels of a pixel on
// distant ground, some rays pass above the ground and some meet it nearer).
vec3 GetAerialPerspectiveVoxel(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                               IN(ScatteringTexture) scattering_texture,
                               IN(ScatteringTexture) single_mie_scattering_texture, IN(vec3) camera,
                               IN(vec3) view_ray, Number w, IN(vec3) sun_direction, OUT(vec3) optical_depth) {
  Number d = AerialPerspectiveSliceDistance(floor(w * Number(AERIAL_PERSPECTIVE_SLICES)));
  vec3 point = camera + view_ray * d;
  Number r_point = length(point);
  if (r_point < atmosphere.bottom_radius) point *= atmosphere.bottom_radius / r_point;
  vec3 transmittance;
  vec3 radiance = GetSkyRadianceToPoint(atmosphere, transmittance_texture, scattering_texture,
                                        single_mie_scattering_texture, camera, point, sun_direction, transmittance);
  optical_depth = -log(max(transmittance, vec3(1e-30)));
  return radiance;
}

// GetSkyRadianceToPoint read from the frame's volume (two fetches) for the
// point at `distance` from the camera seen at `screen_uv`: between two
// slices linear in the distance, and below the first slice in proportion to
// it (both the radiance and the optical depth are 0 at the camera).
vec3 GetSkyRadianceToPointFromVolume(IN(AerialPerspectiveTexture) radiance_volume,
                                     IN(AerialPerspectiveTexture) optical_depth_volume, IN(vec2) screen_uv,
                                     Number distance, OUT(vec3) transmittance) {
  Number slices = Number(AERIAL_PERSPECTIVE_SLICES);
  Number d = max(distance, 0.0);
  Number s = slices * sqrt(d / AERIAL_PERSPECTIVE_MAX_DISTANCE);  // slice k at s = k + 1
  Number k = clamp(floor(s) - 1.0, 0.0, slices - 2.0);
  Number d_k = AerialPerspectiveSliceDistance(k);
  Number t = clamp((d - d_k) / (AerialPerspectiveSliceDistance(k + 1.0) - d_k), 0.0, 1.0);
  Number near = min(d / AerialPerspectiveSliceDistance(0.0), 1.0);
  vec3 uvw = vec3(screen_uv, (k + t + 0.5) / slices);
  transmittance = exp(-vec3(SampleTexture3D(optical_depth_volume, uvw)) * near);
  return vec3(SampleTexture3D(radiance_volume, uvw)) * near;
}
#endif
