// skybake GLSL runtime: ray geometry, and the texture coordinates of a table
// and of the transmittance table. The first of the runtime's sources after
// primitives.glsl and phase_functions.glsl.
//
// This file is compiled twice: as GLSL by the engine (shipped joined with
// the other runtime sources in functions.glsl, in the order of
// kRuntimeFunctionSources, shaders_runtime/snippet.h), and as C++ in double
// precision by the bake and the CPU twin (see runtime.h). Keep it to the
// common subset: Number for scalars, literals written as 1.0 (never 1 for a
// Number), explicit Number() around ints, IN()/OUT() for parameters.
//
// Conventions: positions are relative to the planet centre, in metres; r is a
// distance to the centre, mu the cosine of a view zenith angle, mu_s of the sun
// zenith angle, nu the cosine of the angle between view and sun directions.
// The parameterization follows Bruneton & Neyret 2008 as refined in Bruneton's
// 2017 reference implementation: texels are concentrated near the horizon and
// the ground, and the mu axis is split in two halves (rays that hit the ground
// and rays that do not), so the table is discontinuous at the horizon on purpose.

// Which parts a bake ships (the generated constants define these; a scene
// can leave out tables and the functions that read them). Unset, as in the
// C++ twin, everything is compiled.
#ifndef SKYBAKE_HAS_SCATTERING_TEXTURE
#define SKYBAKE_HAS_SCATTERING_TEXTURE 1
#endif
#ifndef SKYBAKE_HAS_IRRADIANCE_TEXTURE
#define SKYBAKE_HAS_IRRADIANCE_TEXTURE 1
#endif
#ifndef SKYBAKE_HAS_AERIAL_PERSPECTIVE
#define SKYBAKE_HAS_AERIAL_PERSPECTIVE 1
#endif

// ---------------------------------------------------------------------------
// Defensive numerics (ClampCosine, ClampDistance and SafeSqrt are in
// primitives.glsl)

Number ClampRadius(IN(AtmosphereParameters) atmosphere, Number r) {
  return clamp(r, atmosphere.bottom_radius, atmosphere.top_radius);
}

// ---------------------------------------------------------------------------
// Ray-sphere geometry. Each distance is written in the form that avoids
// catastrophic cancellation: of the two roots -r mu +/- sqrt(disc), the one
// that would subtract nearly equal numbers is computed as c / q instead
// (c = product of the roots), which stays accurate for observers a
// millimetre above the ground or rays a microradian off the horizon.

// Distance from radius r along direction cosine mu to the top boundary
// (r <= top_radius).
Number DistanceToTopAtmosphereBoundary(IN(AtmosphereParameters) atmosphere, Number r, Number mu) {
  Number c = (atmosphere.top_radius - r) * (atmosphere.top_radius + r);  // >= 0
  return DistanceToSphereFromInside(r * mu, c);
}

// Distance from radius r along mu to the ground, for a ray that hits it
// (see RayIntersectsGround).
Number DistanceToBottomAtmosphereBoundary(IN(AtmosphereParameters) atmosphere, Number r, Number mu) {
  Number r_mu = r * mu;
  Number c = (r - atmosphere.bottom_radius) * (r + atmosphere.bottom_radius);  // >= 0
  Number s = SafeSqrt(r_mu * r_mu - c);
  return ClampDistance(c / max(s - r_mu, 1e-30));
}

bool RayIntersectsGround(IN(AtmosphereParameters) atmosphere, Number r, Number mu) {
  Number c = (r - atmosphere.bottom_radius) * (r + atmosphere.bottom_radius);
  return mu < 0.0 && r * r * mu * mu >= c;
}

// Distance to the boundary the ray leaves through: the ground if it hits it,
// else the top of the atmosphere.
Number DistanceToNearestAtmosphereBoundary(IN(AtmosphereParameters) atmosphere, Number r, Number mu,
                                           bool ray_r_mu_intersects_ground) {
  return ray_r_mu_intersects_ground ? DistanceToBottomAtmosphereBoundary(atmosphere, r, mu)
                                    : DistanceToTopAtmosphereBoundary(atmosphere, r, mu);
}

// Radius and direction cosine at distance d along the ray (r, mu).
Number RadiusAtDistance(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number d) {
  return ClampRadius(atmosphere, sqrt(d * d + 2.0 * r * mu * d + r * r));
}

Number CosineAtDistance(Number r, Number mu, Number d, Number r_d) {
  return ClampCosine((r * mu + d) / r_d);
}

// Where a ray from `camera` along `view_ray` starts inside the atmosphere:
// the camera itself if it is inside, else the entry point at the near root d
// of the ray / top-sphere quadratic d^2 + 2 r_mu d + r^2 - top^2 = 0, written
// as c / (sqrt(disc) - r_mu) to avoid cancellation. r and r_mu =
// dot(entry, view_ray) are those of the entry. False if the ray misses the
// atmosphere.
bool EnterAtmosphere(IN(AtmosphereParameters) atmosphere, IN(vec3) camera, IN(vec3) view_ray, OUT(vec3) entry,
                     OUT(Number) r, OUT(Number) r_mu) {
  entry = camera;
  r = length(camera);
  r_mu = dot(camera, view_ray);
  if (r > atmosphere.top_radius) {
    Number c = (r - atmosphere.top_radius) * (r + atmosphere.top_radius);
    Number disc = r_mu * r_mu - c;
    if (r_mu >= 0.0 || disc < 0.0) return false;
    Number distance_to_top = c / (SafeSqrt(disc) - r_mu);
    entry = camera + view_ray * distance_to_top;
    r = atmosphere.top_radius;
    r_mu += distance_to_top;
  }
  return true;
}

// The ray from `camera` along `view_ray` from where it starts inside the
// atmosphere (EnterAtmosphere): that start, its radius r, the cosines mu of
// the ray and mu_s of the sun along `sun_direction` there, and nu between the
// two. False if the ray misses the atmosphere.
bool GetViewRayStart(IN(AtmosphereParameters) atmosphere, IN(vec3) camera, IN(vec3) view_ray,
                     IN(vec3) sun_direction, OUT(vec3) start, OUT(Number) r, OUT(Number) mu, OUT(Number) mu_s,
                     OUT(Number) nu) {
  Number r_mu;
  if (!EnterAtmosphere(atmosphere, camera, view_ray, start, r, r_mu)) return false;
  mu = ClampCosine(r_mu / r);
  mu_s = ClampCosine(dot(start, sun_direction) / r);
  nu = ClampCosine(dot(view_ray, sun_direction));
  return true;
}

// ---------------------------------------------------------------------------
// Texture coordinates. A table of n texels samples the unit range at texel
// centres, so [0, 1] maps to [0.5 / n, 1 - 0.5 / n].

Number GetTextureCoordFromUnitRange(Number x, int texture_size) {
  return 0.5 / Number(texture_size) + x * (1.0 - 1.0 / Number(texture_size));
}

Number GetUnitRangeFromTextureCoord(Number u, int texture_size) {
  return (u - 0.5 / Number(texture_size)) / (1.0 - 1.0 / Number(texture_size));
}

// Distance from the ground to the top boundary along the horizon ray from the
// top boundary, i.e. the length of a ray tangent to the ground.
Number HorizonDistanceAtTop(IN(AtmosphereParameters) atmosphere) {
  return sqrt((atmosphere.top_radius - atmosphere.bottom_radius) *
              (atmosphere.top_radius + atmosphere.bottom_radius));
}

// Distance from radius r to the horizon (0 on the ground).
Number HorizonDistance(IN(AtmosphereParameters) atmosphere, Number r) {
  return DistanceToHorizon(atmosphere.bottom_radius, r);
}

// Transmittance table: x = mu through the distance to the top boundary
// (rays above the horizon only), y = r through the distance to the horizon.
vec2 GetTransmittanceTextureUvFromRMu(IN(AtmosphereParameters) atmosphere, Number r, Number mu) {
  Number H = HorizonDistanceAtTop(atmosphere);
  Number rho = HorizonDistance(atmosphere, r);
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, r, mu);
  Number d_min = atmosphere.top_radius - r;
  Number d_max = rho + H;
  Number x_mu = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
  Number x_r = rho / H;
  return vec2(GetTextureCoordFromUnitRange(x_mu, atmosphere.transmittance_width),
              GetTextureCoordFromUnitRange(x_r, atmosphere.transmittance_height));
}

