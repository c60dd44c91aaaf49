// skybake GLSL runtime: geometry, table parameterization and lookups, and the
// functions an engine calls (sky radiance, aerial perspective, irradiance).
//
// This file is compiled twice: as GLSL by the engine, after definitions.glsl,
// the generated constants, primitives.glsl and phase_functions.glsl (shipped
// joined with this file), and as C++ in double precision by the bake and the
// CPU twin (see runtime.h). Keep it to the common subset: Number for
// scalars, literals written as 1.0 (never 1 for a Number), explicit Number()
// around ints, IN()/OUT() for parameters.
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

#if SKYBAKE_HAS_SCATTERING_TEXTURE
// The view zenith axis of the scattering table and of the sky view
// (per_frame.glsl): split at the horizon into two halves, rays that hit the
// ground in the lower one and the others in the upper one. Within its half a
// ray's unit x in [0, 1] is its distance to the boundary it leaves through,
// 0 looking straight up or down and 1 at the horizon: to the ground between
// r - bottom and rho (the distance to the horizon), to the top boundary
// between top - r and rho + H.
Number GetUnitMuInHalf(IN(AtmosphereParameters) atmosphere, Number r, Number rho, Number mu,
                       bool ray_r_mu_intersects_ground) {
  if (ray_r_mu_intersects_ground) {
    Number d = DistanceToBottomAtmosphereBoundary(atmosphere, r, mu);
    Number d_min = r - atmosphere.bottom_radius;
    return rho == d_min ? 0.0 : (d - d_min) / (rho - d_min);
  }
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, r, mu);
  Number d_min = atmosphere.top_radius - r;
  Number d_max = rho + HorizonDistanceAtTop(atmosphere);
  return d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
}

// Its inverse: the view zenith cosine at unit x within the half, from
// bottom^2 = r^2 + 2 r mu d + d^2 (ground) or top^2 = r^2 + 2 r mu d + d^2
// with top^2 - r^2 = H^2 - rho^2.
Number GetMuFromUnitMuInHalf(IN(AtmosphereParameters) atmosphere, Number r, Number rho, Number x,
                             bool ray_r_mu_intersects_ground) {
  if (ray_r_mu_intersects_ground) {
    Number d_min = r - atmosphere.bottom_radius;
    Number d = d_min + (rho - d_min) * x;
    return d == 0.0 ? -1.0 : ClampCosine(-(rho * rho + d * d) / (2.0 * r * d));
  }
  Number H = HorizonDistanceAtTop(atmosphere);
  Number d_min = atmosphere.top_radius - r;
  Number d = d_min + (rho + H - d_min) * x;
  return d == 0.0 ? 1.0 : ClampCosine((H * H - rho * rho - d * d) / (2.0 * r * d));
}

// The texture coordinate of unit x within its half of a mu axis of `size`
// texels: the lower half's x runs down from the middle to 0, the upper
// half's up to 1, each sampled at its own texel centres.
Number GetTextureCoordFromUnitMuInHalf(Number x, bool ray_r_mu_intersects_ground, int size) {
  Number u = 0.5 * GetTextureCoordFromUnitRange(x, size / 2);
  return ray_r_mu_intersects_ground ? 0.5 - u : 0.5 + u;
}

// Its inverse: the half a texture coordinate lies in, and x there.
Number GetUnitMuInHalfFromTextureCoord(Number u, int size, OUT(bool) ray_r_mu_intersects_ground) {
  ray_r_mu_intersects_ground = u < 0.5;
  return GetUnitRangeFromTextureCoord(ray_r_mu_intersects_ground ? 1.0 - 2.0 * u : 2.0 * u - 1.0, size / 2);
}

// A of ScatteringUnitMuSFromDistance: the distance to the top boundary from
// the ground for the sun at scattering_mu_s_min, over its range from d_min =
// top - bottom (the sun at the zenith) to d_max = HorizonDistanceAtTop.
Number GetScatteringLowestSunDistance(IN(AtmosphereParameters) atmosphere) {
  Number d_min = atmosphere.top_radius - atmosphere.bottom_radius;
  Number d_max = HorizonDistanceAtTop(atmosphere);
  Number D = DistanceToTopAtmosphereBoundary(atmosphere, atmosphere.bottom_radius, atmosphere.scattering_mu_s_min);
  return (D - d_min) / (d_max - d_min);
}

// mu_s through the distance to the top boundary from the ground, rescaled so
// that scattering_mu_s_min maps to 0 and more texels go to low suns, then
// stretched so that scattering_mu_s_max maps to 1. (Independent of r: the
// bake maps the sun's cosine along a ray with it alone.)
Number GetScatteringUnitMuS(IN(AtmosphereParameters) atmosphere, Number mu_s) {
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, atmosphere.bottom_radius, mu_s);
  Number d_min = atmosphere.top_radius - atmosphere.bottom_radius;
  Number d_max = HorizonDistanceAtTop(atmosphere);
  Number a = (d - d_min) / (d_max - d_min);
  return ScatteringUnitMuSFromDistance(a, 1.0 / GetScatteringLowestSunDistance(atmosphere));
}

// The inverse of GetScatteringUnitMuS stretched to [0, 1]: the sun cosine
// at x in [0, 1] along the table's mu_s axis (x = column / (size - 1) at a
// texel column): a by ScatteringDistanceFromUnitMuS, then d, and mu_s from
// top^2 = bottom^2 + 2 bottom mu_s d + d^2.
Number GetScatteringMuSFromUnitRange(IN(AtmosphereParameters) atmosphere, Number x) {
  Number x_mu_s = x * GetScatteringUnitMuS(atmosphere, atmosphere.scattering_mu_s_max);
  Number bottom = atmosphere.bottom_radius;
  Number H = HorizonDistanceAtTop(atmosphere);
  Number d_min = atmosphere.top_radius - bottom;
  Number d_max = H;
  Number A = GetScatteringLowestSunDistance(atmosphere);
  Number a = ScatteringDistanceFromUnitMuS(x_mu_s, 1.0 / A);
  Number d = d_min + min(a, A) * (d_max - d_min);
  return d == 0.0 ? 1.0 : ClampCosine((H * H - d * d) / (2.0 * bottom * d));
}

Number GetScatteringTextureUMuS(IN(AtmosphereParameters) atmosphere, Number mu_s) {
  Number x = GetScatteringUnitMuS(atmosphere, mu_s) /
             GetScatteringUnitMuS(atmosphere, atmosphere.scattering_mu_s_max);
  return GetTextureCoordFromUnitRange(min(x, 1.0), atmosphere.scattering_mu_s_size);
}

// ---------------------------------------------------------------------------
// The sun axis after sunset. From column scattering_mu_s_split up the
// scattering tables' mu_s columns lie at the same suns for every ray
// (GetScatteringMuSFromUnitRange); below it, where the split is above 0,
// every ray (r, mu) and sun azimuth from the view has its own columns,
// placed from its shadow edge E (ShadowEdgeSunZenith), the sun zenith angle
// past which no point of the ray sees the sun. After sunset a ray's single
// scattering falls off a cliff where its last lit point sets, by orders of
// magnitude within a fraction of a degree, at a sun that differs from ray
// to ray; on columns at the same suns for every ray the lookup's blend
// between two of them misses it in either direction, and light in the
// Earth's shadow read as bright (docs/accuracy.md, "Twilight: a sun axis
// measured from each ray's shadow edge"). Of a ray's own columns,
// SHADOW_EDGE_PAST_COLUMNS lie at and past E (the last of them at E, the
// others evenly up to the tables' lowest sun, at least
// SHADOW_EDGE_LEAST_PAST_SPAN past E), where single scattering is 0 and
// only the higher orders remain; the others on the lit side, from
// SHADOW_EDGE_CLOSEST before E to the split, at even steps of
// ShadowEdgeLitUnit. The bake puts the split at the lowest column at most
// 83 degrees from the zenith: above it the sun is up for every point of
// every ray. Past a ray's first column (its lowest sun) the lookup
// continues the fall of the first two.
const int SHADOW_EDGE_PAST_COLUMNS = 6;
const Number SHADOW_EDGE_TABLES_WEIGHT = 0.3;
const Number SHADOW_EDGE_CLOSEST = 8.726646259971648e-4;          // 0.05 degrees
const Number SHADOW_EDGE_LEAST_PAST_SPAN = 0.03490658503988659;  // 2 degrees

// The cosine of the azimuth between the view (zenith cosine mu) and the sun
// (mu_s) at the cosine nu between them: nu = mu mu_s + sqrt((1 - mu^2)
// (1 - mu_s^2)) cos(phi); 1 where the azimuth is undefined.
Number ViewSunAzimuthCosine(Number mu, Number mu_s, Number nu) {
  Number across = SafeSqrt((1.0 - mu * mu) * (1.0 - mu_s * mu_s));
  return across > 0.0 ? ClampCosine((nu - mu * mu_s) / across) : 1.0;
}

// The sun zenith angle E past which no point of the ray (r, mu) sees any
// of the sun's disc, for the sun at azimuth phi from the view. The Earth's
// shadow is a half cylinder behind the planet, so the last lit point of a
// ray is one of its ends: the start, lit while the sun is above its horizon
// (zenith cosine -c(r), HorizonZenithCosine), or the far end, seen from the
// start at angle alpha around the planet's centre, where the sun's cosine
// is cos(theta) cos(alpha) + sin(theta) sin(alpha) cos(phi) =
// rho cos(theta - beta), rho cos(beta) = cos(alpha), rho sin(beta) =
// sin(alpha) cos(phi), above the far end's horizon until theta = beta +
// gamma, gamma = acos(c(r_end) / rho). Plus the disc's angular radius: its
// top sets last.
//
// The lookup places a ray's own columns by E and by the sun's distance to
// it, D = E - theta, from a twentieth of a degree (SHADOW_EDGE_CLOSEST)
// on, so both must be right to far better than that. GPUs approximate acos
// and atan loosely (the GLSL specifications allow it; on Mesa's llvmpipe
// acos is off by up to 1.6e-4 rad, atan by 3e-6), so the lookup never
// takes an angle from them: E is carried as the direction (cos E, sin E),
// composed from the cosines and sines of the angles above, and enters the
// lookup as differences of angles (ShadowEdgeDistance, whose atan of a
// small angle errs relatively, by 2e-5 on llvmpipe) and as cosines
// (ShadowEdgeSunCosine). The angle itself (for the bake) is returned.
Number ShadowEdge(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number cos_phi,
                  bool ray_r_mu_intersects_ground, OUT(vec2) direction) {
  Number d = DistanceToNearestAtmosphereBoundary(atmosphere, r, mu, ray_r_mu_intersects_ground);
  Number r_d = RadiusAtDistance(atmosphere, r, mu, d);
  Number cos_alpha = ClampCosine((r + d * mu) / r_d);
  Number across = d * SafeSqrt(1.0 - mu * mu) / r_d * cos_phi;
  Number rho = sqrt(across * across + cos_alpha * cos_alpha);
  Number c_end = -HorizonZenithCosine(atmosphere.bottom_radius, r_d);
  Number c_start = HorizonZenithCosine(atmosphere.bottom_radius, r);
  vec2 start = vec2(c_start, atmosphere.bottom_radius / r);
  Number cos_gamma = -c_end / rho;
  Number sin_gamma = SafeSqrt(1.0 - cos_gamma * cos_gamma);
  vec2 end = c_end >= rho ? vec2(-1.0, 0.0)
                          : vec2(cos_alpha * cos_gamma - across * sin_gamma, across * cos_gamma + cos_alpha * sin_gamma) /
                                rho;
  // The end that sets last has the smaller cosine (both angles lie in
  // [0, pi], unless beta + gamma passes pi, where the sine is negative).
  bool end_sets_last = end.y < 0.0 || end.x < start.x;
  // The disc's radius a by its series (a is below 0.01: to 1e-14), free of
  // the GPU's sin and cos, whose absolute errors are large next to a.
  Number a = atmosphere.sun_angular_radius;
  Number cos_a = 1.0 - 0.5 * a * a * (1.0 - a * a / 12.0);
  Number sin_a = a * (1.0 - a * a / 6.0);
  vec2 last = end_sets_last ? end : start;
  direction = vec2(last.x * cos_a - last.y * sin_a, last.y * cos_a + last.x * sin_a);
  Number angle = end_sets_last ? (c_end >= rho ? PI : atan(across, cos_alpha) + acos(cos_gamma)) : acos(c_start);
  return angle + a;
}

Number ShadowEdgeSunZenith(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number cos_phi,
                           bool ray_r_mu_intersects_ground) {
  vec2 unused;
  return ShadowEdge(atmosphere, r, mu, cos_phi, ray_r_mu_intersects_ground, unused);
}

// The direction (cos E, sin E) of an edge given as an angle (the bake's).
vec2 ShadowEdgeDirection(Number edge) { return vec2(cos(edge), sin(edge)); }

// D = E - theta for the edge's direction (cos E, sin E) and the sun at
// zenith cosine mu_s: atan(sin(E - theta), cos(E - theta)), as accurate
// near the edge as the arithmetic.
Number ShadowEdgeDistance(IN(vec2) edge, Number mu_s) {
  Number sin_theta = SafeSqrt(1.0 - mu_s * mu_s);
  return atan(edge.y * mu_s - edge.x * sin_theta, edge.x * mu_s + edge.y * sin_theta);
}

// The sun's zenith cosine at distance D to the edge: cos(E - D).
Number ShadowEdgeSunCosine(IN(vec2) edge, Number D) { return edge.x * cos(D) + edge.y * sin(D); }

// The sun cosine of the split's column.
Number GetScatteringSplitMuS(IN(AtmosphereParameters) atmosphere) {
  return GetScatteringMuSFromUnitRange(
      atmosphere, Number(atmosphere.scattering_mu_s_split) / Number(atmosphere.scattering_mu_s_size - 1));
}

// X, a unit sun from 1 at the zenith to 0 at the tables' lowest sun (and
// on below it, negative and smooth), like GetScatteringUnitMuS but with
// Bruneton's k = 1, at sun zenith cosine mu_s, and its derivative in the
// sun zenith angle theta: with a = (d - d_min) / (d_max - d_min) (as there)
// and A its value at scattering_mu_s_min, X = (1 - a / A) / (1 + a); d =
// -R mu_s + sqrt(R^2 mu_s^2 + top^2 - R^2) (R the bottom radius) has dd/dmu_s
// = -R d / (d + R mu_s) and dmu_s/dtheta = -sin(theta).
Number ShadowEdgeUnitSun(IN(AtmosphereParameters) atmosphere, Number mu_s, OUT(Number) derivative) {
  Number bottom = atmosphere.bottom_radius;
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, bottom, mu_s);
  Number d_min = atmosphere.top_radius - bottom;
  Number span = HorizonDistanceAtTop(atmosphere) - d_min;
  Number a = (d - d_min) / span;
  Number inverse_A = 1.0 / GetScatteringLowestSunDistance(atmosphere);
  Number da_dtheta = bottom * d / (d + bottom * mu_s) / span * SafeSqrt(1.0 - mu_s * mu_s);
  derivative = -(inverse_A + 1.0) / ((1.0 + a) * (1.0 + a)) * da_dtheta;
  return (1.0 - a * inverse_A) / (1.0 + a);
}

// The position in [0, 1] between a ray's lit columns of the sun at
// distance D = E - theta from its edge (at least SHADOW_EDGE_CLOSEST, at
// most the split's E - theta_split):
//   x = w (X(E - D) - X(E - D_min)) / (X(theta_split) - X(E - D_min))
//       + (1 - w) ln(D / D_min) / ln((E - theta_split) / D_min),
// w = SHADOW_EDGE_TABLES_WEIGHT, D_min = SHADOW_EDGE_CLOSEST. The logarithm
// closes in on the edge, near which the light falls as D^3 (the disc's
// smooth step times the lit stretch) and farther out as fast as the
// sunlight's grazing path thickens; X keeps the tables' density of columns
// toward a low sun, where light grazing the ground changes fast too. From
// the edge's X(E - D_min) (X_closest), X(theta_split) - X(E - D_min)
// (X_span) and ln((E - theta_split) / D_min) (log_span); also dx/ds in
// s = ln D.
Number ShadowEdgeLitUnitFrom(IN(AtmosphereParameters) atmosphere, Number D, IN(vec2) edge, Number X_closest,
                             Number X_span, Number log_span, OUT(Number) derivative) {
  Number dX_dtheta;
  Number X = ShadowEdgeUnitSun(atmosphere, ShadowEdgeSunCosine(edge, D), dX_dtheta);
  derivative = -SHADOW_EDGE_TABLES_WEIGHT * dX_dtheta * D / X_span + (1.0 - SHADOW_EDGE_TABLES_WEIGHT) / log_span;
  return SHADOW_EDGE_TABLES_WEIGHT * (X - X_closest) / X_span +
         (1.0 - SHADOW_EDGE_TABLES_WEIGHT) * log(D / SHADOW_EDGE_CLOSEST) / log_span;
}

// ShadowEdgeLitUnitFrom's constants for the edge, and the split's D.
void ShadowEdgeLitUnitSpans(IN(AtmosphereParameters) atmosphere, IN(vec2) edge, OUT(Number) X_closest,
                            OUT(Number) X_span, OUT(Number) log_span, OUT(Number) split_distance) {
  Number unused;
  Number split_mu_s = GetScatteringSplitMuS(atmosphere);
  X_closest = ShadowEdgeUnitSun(atmosphere, ShadowEdgeSunCosine(edge, SHADOW_EDGE_CLOSEST), unused);
  X_span = ShadowEdgeUnitSun(atmosphere, split_mu_s, unused) - X_closest;
  split_distance = ShadowEdgeDistance(edge, split_mu_s);
  log_span = log(split_distance / SHADOW_EDGE_CLOSEST);
}

Number ShadowEdgeLitUnit(IN(AtmosphereParameters) atmosphere, Number distance, IN(vec2) edge) {
  Number X_closest;
  Number X_span;
  Number log_span;
  Number split_distance;
  ShadowEdgeLitUnitSpans(atmosphere, edge, X_closest, X_span, log_span, split_distance);
  Number unused;
  return ShadowEdgeLitUnitFrom(atmosphere, clamp(distance, SHADOW_EDGE_CLOSEST, split_distance), edge, X_closest,
                               X_span, log_span, unused);
}

// Its inverse: D at position x in [0, 1], by Newton's method in s = ln D
// from the logarithm's term alone (x rises with s, at least at 1 - w times
// the logarithm's rate), to 1e-11 in ln D in a few steps.
Number ShadowEdgeLitDistance(IN(AtmosphereParameters) atmosphere, Number x, IN(vec2) edge) {
  Number X_closest;
  Number X_span;
  Number log_span;
  Number split_distance;
  ShadowEdgeLitUnitSpans(atmosphere, edge, X_closest, X_span, log_span, split_distance);
  Number s_min = log(SHADOW_EDGE_CLOSEST);
  Number s_max = s_min + log_span;
  Number s = mix(s_min, s_max, x);
  for (int i = 0; i < 12; ++i) {
    Number slope;
    Number error = ShadowEdgeLitUnitFrom(atmosphere, exp(s), edge, X_closest, X_span, log_span, slope) - x;
    Number next = clamp(s - error / slope, s_min, s_max);
    bool converged = abs(next - s) < 1e-11;
    s = next;
    if (converged) break;
  }
  return exp(s);
}

// The span in sun zenith angle between two of a ray's columns past its
// edge E: evenly from E to the tables' lowest sun, or at least
// SHADOW_EDGE_LEAST_PAST_SPAN past E.
Number ShadowEdgePastStep(IN(AtmosphereParameters) atmosphere, IN(vec2) edge) {
  Number past_lowest = -ShadowEdgeDistance(edge, atmosphere.scattering_mu_s_min);
  return max(past_lowest, SHADOW_EDGE_LEAST_PAST_SPAN) / Number(SHADOW_EDGE_PAST_COLUMNS - 1);
}

// The position, in columns from the first, of the sun at distance D to the
// edge (ShadowEdgeDistance) below the split, for a ray whose edge's
// direction is `edge`: between the lit columns at x (ShadowEdgeLitUnit);
// within SHADOW_EDGE_CLOSEST of the edge, in proportion to D between the
// columns at E and D_min; past the edge, in proportion to the angle past it
// (negative past the first column).
Number GetScatteringShadowEdgePosition(IN(AtmosphereParameters) atmosphere, Number D, IN(vec2) edge) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  if (D >= SHADOW_EDGE_CLOSEST) {
    return past + ShadowEdgeLitUnit(atmosphere, D, edge) * (Number(atmosphere.scattering_mu_s_split) - past);
  }
  if (D >= 0.0) return past - 1.0 + D / SHADOW_EDGE_CLOSEST;
  return past - 1.0 + D / ShadowEdgePastStep(atmosphere, edge);
}

// Its inverse: the sun's distance D to the edge at `position`.
Number GetScatteringShadowEdgeDistance(IN(AtmosphereParameters) atmosphere, Number position, IN(vec2) edge) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  if (position >= past) {
    Number x = (position - past) / (Number(atmosphere.scattering_mu_s_split) - past);
    return ShadowEdgeLitDistance(atmosphere, x, edge);
  }
  if (position >= past - 1.0) return (position - past + 1.0) * SHADOW_EDGE_CLOSEST;
  return (position - past + 1.0) * ShadowEdgePastStep(atmosphere, edge);
}

// r over the table's radii: rows at evenly spaced distances to the horizon
// rho, which crowds them near the ground (at h = rho^2 / (r + bottom)), and
// between two rows linear in rho, except for a ray that hits the ground.
// Such a ray gathers light about in proportion to its length d, and at the
// lower half's mu coordinate x (below) d = h (1 - x) + rho x: there the
// position between the rows is linear in that d at the ray's own x. (Linear
// in rho, a camera 10 m up looking straight down, d = h, read 150 % high
// between the rows at 0 and 63 m.)
Number GetScatteringTextureUR(IN(AtmosphereParameters) atmosphere, Number r, Number rho,
                              bool ray_r_mu_intersects_ground, Number x_mu) {
  Number rho_min = HorizonDistance(atmosphere, atmosphere.scattering_r_min);
  Number rho_max = HorizonDistance(atmosphere, atmosphere.scattering_r_max);
  Number last_row = Number(atmosphere.scattering_r_size - 1);
  Number position = clamp((rho - rho_min) / (rho_max - rho_min), 0.0, 1.0) * last_row;
  if (!ray_r_mu_intersects_ground) return (position + 0.5) / (last_row + 1.0);
  Number row = min(floor(position), last_row - 1.0);
  Number rho_below = mix(rho_min, rho_max, row / last_row);
  Number rho_above = mix(rho_min, rho_max, (row + 1.0) / last_row);
  Number bottom = atmosphere.bottom_radius;
  Number d_below = mix(HeightFromHorizonDistance(bottom, rho_below), rho_below, x_mu);
  Number d_above = mix(HeightFromHorizonDistance(bottom, rho_above), rho_above, x_mu);
  Number d = mix(r - bottom, rho, x_mu);
  Number t = clamp((d - d_below) / (d_above - d_below), 0.0, 1.0);
  return (row + t + 0.5) / (last_row + 1.0);
}

// 4D scattering table, stored as a 3D texture: x packs nu (slowest) and mu_s,
// y is mu, z is r. Returns (u_nu, u_mu_s, u_mu, u_r) in [0, 1]; below the
// split also the ray's shadow edge (ShadowEdge's direction), which
// GetScattering reads again, else (0, 0).
vec4 GetScatteringTextureUvwzAndEdge(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number mu_s, Number nu,
                                     bool ray_r_mu_intersects_ground, OUT(vec2) edge) {
  Number rho = HorizonDistance(atmosphere, r);

  Number x_mu = GetUnitMuInHalf(atmosphere, r, rho, mu, ray_r_mu_intersects_ground);
  Number u_mu = GetTextureCoordFromUnitMuInHalf(x_mu, ray_r_mu_intersects_ground, atmosphere.scattering_mu_size);
  Number u_r = GetScatteringTextureUR(atmosphere, r, rho, ray_r_mu_intersects_ground, x_mu);

  // Below the split, the position on the ray's own columns.
  Number u_mu_s = GetScatteringTextureUMuS(atmosphere, mu_s);
  Number mu_s_size = Number(atmosphere.scattering_mu_s_size);
  edge = vec2(0.0);
  if (atmosphere.scattering_mu_s_split > 0 && u_mu_s * mu_s_size - 0.5 < Number(atmosphere.scattering_mu_s_split)) {
    ShadowEdge(atmosphere, r, mu, ViewSunAzimuthCosine(mu, mu_s, nu), ray_r_mu_intersects_ground, edge);
    u_mu_s = (GetScatteringShadowEdgePosition(atmosphere, ShadowEdgeDistance(edge, mu_s), edge) + 0.5) / mu_s_size;
  }
  return vec4(ScatteringUnitNu(nu), u_mu_s, u_mu, u_r);
}

vec4 GetScatteringTextureUvwzFromRMuMuSNu(IN(AtmosphereParameters) atmosphere, Number r, Number mu,
                                          Number mu_s, Number nu, bool ray_r_mu_intersects_ground) {
  vec2 unused;
  return GetScatteringTextureUvwzAndEdge(atmosphere, r, mu, mu_s, nu, ray_r_mu_intersects_ground, unused);
}
#endif

// Below this sun cosine (84 degrees) table lookups interpolate along mu_s
// in ln L: the irradiance geometrically (SunCosineMix), the scattering table
// by a monotone cubic over four columns (LogMonotoneCubicMix).
const Number LOW_SUN_MU_S = 0.1;

#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
// Irradiance table: x = mu_s (over [mu_s_min, 1], see below), y = r (as
// rho / H). r as rho / H, like the other tables: texels crowd near the
// ground, where the sky irradiance falls fastest with altitude (linear in
// r, 16 texels read 4% high at 1 and 10 km). mu_s over the covered
// [mu_s_min, 1] only: below the horizon the irradiance falls by an order of
// magnitude within a few degrees, and texels below mu_s_min would be
// wasted.
//
// Along mu_s, half of the columns lie evenly over [mu_s_min, knee] and half
// over [knee, 1], knee = LOW_SUN_MU_S when mu_s_min is below it (else the
// middle of the range, which makes the axis linear): from low sun to the
// end of twilight the sky irradiance falls by orders of magnitude, and in
// daylight it changes slowly (docs/accuracy.md measures both).
Number IrradianceKneeMuS(IN(AtmosphereParameters) atmosphere) {
  return atmosphere.mu_s_min < LOW_SUN_MU_S ? LOW_SUN_MU_S : 0.5 * (atmosphere.mu_s_min + 1.0);
}

// The unit x in [0, 1] of mu_s in [mu_s_min, 1] (below 0 under mu_s_min).
Number GetIrradianceUnitMuS(IN(AtmosphereParameters) atmosphere, Number mu_s) {
  Number knee = IrradianceKneeMuS(atmosphere);
  return mu_s < knee ? 0.5 * (mu_s - atmosphere.mu_s_min) / (knee - atmosphere.mu_s_min)
                     : 0.5 + 0.5 * (mu_s - knee) / (1.0 - knee);
}

// Its inverse.
Number GetIrradianceMuSFromUnit(IN(AtmosphereParameters) atmosphere, Number x) {
  Number knee = IrradianceKneeMuS(atmosphere);
  return x < 0.5 ? atmosphere.mu_s_min + 2.0 * x * (knee - atmosphere.mu_s_min)
                 : knee + (2.0 * x - 1.0) * (1.0 - knee);
}

vec2 GetIrradianceTextureUvFromRMuS(IN(AtmosphereParameters) atmosphere, Number r, Number mu_s) {
  Number x_r = HorizonDistance(atmosphere, r) / HorizonDistanceAtTop(atmosphere);
  Number x_mu_s = clamp(GetIrradianceUnitMuS(atmosphere, mu_s), 0.0, 1.0);
  return vec2(GetTextureCoordFromUnitRange(x_mu_s, atmosphere.irradiance_width),
              GetTextureCoordFromUnitRange(x_r, atmosphere.irradiance_height));
}
#endif

// ---------------------------------------------------------------------------
// Table lookups.

// The transmittance table stores optical depth to the top boundary, so the
// transmittance between two points is exp(-(tau_x - tau_y)): it cannot form
// 0/0 when both transmittances underflow, and it is never above 1.
vec3 GetOpticalDepthToTopAtmosphereBoundary(IN(AtmosphereParameters) atmosphere,
                                            IN(TransmittanceTexture) transmittance_texture,
                                            Number r, Number mu) {
  vec2 uv = GetTransmittanceTextureUvFromRMu(atmosphere, r, mu);
  return vec3(SampleTexture2D(transmittance_texture, uv));
}

vec3 GetTransmittanceToTopAtmosphereBoundary(IN(AtmosphereParameters) atmosphere,
                                             IN(TransmittanceTexture) transmittance_texture,
                                             Number r, Number mu) {
  return exp(-GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, mu));
}

// Optical depth between the point at radius r and the point at distance d
// along mu, from lookups of rays that point up only: a segment that descends
// all the way (every segment of a ray that hits the ground) is looked up
// reversed, and one that passes its lowest point is split there. The two
// lookups then see the same segment from the same side whichever end the
// camera is at, so the result does not depend on the direction (a downward
// lookup passing the lowest point would subtract two large, separately
// interpolated optical depths of near-horizon rays: errors of 0.2 in the
// transmittance at the stress tables' 64 x 16), and the values subtracted
// are the smaller ones, of the upward rays.
vec3 GetOpticalDepth(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                     Number r, Number mu, Number d, bool ray_r_mu_intersects_ground) {
  Number r_d = RadiusAtDistance(atmosphere, r, mu, d);
  Number mu_d = CosineAtDistance(r, mu, d, r_d);
  vec3 tau;
  if (ray_r_mu_intersects_ground || mu_d < 0.0) {
    tau = GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r_d, -mu_d) -
          GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, -mu);
  } else if (mu >= 0.0) {
    tau = GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, mu) -
          GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r_d, mu_d);
  } else {
    // Down to the lowest point, at radius r sqrt(1 - mu^2), then up.
    Number r_low = ClampRadius(atmosphere, r * SafeSqrt(1.0 - mu * mu));
    vec3 tau_low = GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r_low, 0.0);
    tau = max(tau_low - GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, -mu),
              vec3(0.0)) +
          max(tau_low - GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r_d, mu_d),
              vec3(0.0));
  }
  return max(tau, vec3(0.0));
}

vec3 GetTransmittance(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                      Number r, Number mu, Number d, bool ray_r_mu_intersects_ground) {
  return exp(-GetOpticalDepth(atmosphere, transmittance_texture, r, mu, d, ray_r_mu_intersects_ground));
}

// Fraction of the sun's disc above the horizon seen from radius r, by a
// smooth step over the disc's angular size (Bruneton 2017).
Number SunVisibleFraction(IN(AtmosphereParameters) atmosphere, Number r, Number mu_s) {
  Number sin_theta_h = atmosphere.bottom_radius / r;
  return SunVisibleFractionAboveHorizon(mu_s, HorizonZenithCosine(atmosphere.bottom_radius, r),
                                        sin_theta_h * atmosphere.sun_angular_radius);
}

vec3 GetTransmittanceToSun(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                           Number r, Number mu_s) {
  return GetTransmittanceToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, mu_s) *
         SunVisibleFraction(atmosphere, r, mu_s);
}

// Interpolation between two table texels a and b along the sun's cosine (or
// between two nu slices of one mu_s texel column), at position t in [0, 1]
// (below 0 under the table's lowest sun, see SunBelowTableMix):
// linear, or, where `low_sun` (the texel with the lower sun has mu_s below
// LOW_SUN_MU_S), geometric, a^(1 - t) b^t. From low sun to the end of
// twilight the light falls by orders of magnitude over a few mu_s texels,
// about as exp(-h / H) with h the height of the Earth's shadow (or, before
// sunset, the sun's air mass), and linear interpolation overestimates such a
// fall by up to (a + b) / (2 sqrt(a b)) at mid-texel: 1.7 times at a tenfold
// fall. Where one side is dark (0), the result falls to it within the texel.
vec4 SunCosineMix(vec4 a, vec4 b, Number t, bool low_sun) {
  if (!low_sun) return mix(a, b, t);
  vec4 dark = vec4(1e-30);
  return exp(mix(log(max(a, dark)), log(max(b, dark)), t)) * step(dark, max(a, b));
}

// The position t between two mu_s texels, in [0, 1], except below the
// table's lowest sun (t < 0) among low suns, where the geometric blend goes
// on: the light keeps falling as it fell between the two lowest texels.
Number SunCosinePosition(Number t, bool low_sun) {
  return low_sun ? min(t, 1.0) : clamp(t, 0.0, 1.0);
}

// SunCosineMix, never brighter than the lowest texel below the table's
// lowest sun (where the two lowest texels did not fall, the blend would rise).
vec4 SunBelowTableMix(vec4 a, vec4 b, Number t, bool low_sun) {
  vec4 blend = SunCosineMix(a, b, t, low_sun);
  return t < 0.0 ? min(blend, a) : blend;
}

#if SKYBAKE_HAS_SCATTERING_TEXTURE
// The two scattering-table mu_s texel columns a lookup at unit mu_s u_mu_s
// blends: their x coordinates within a nu slice, the position between them
// (SunCosinePosition) and whether the lower one is a low sun, that is below
// x_low_sun = GetScatteringTextureUMuS(atmosphere, LOW_SUN_MU_S), which the
// caller computes once.
void GetScatteringMuSColumns(IN(AtmosphereParameters) atmosphere, Number u_mu_s, Number x_low_sun,
                             OUT(Number) x_below, OUT(Number) x_above, OUT(Number) mu_s_t,
                             OUT(bool) low_sun_below) {
  Number mu_s_size = Number(atmosphere.scattering_mu_s_size);
  Number mu_s_coord = u_mu_s * mu_s_size - 0.5;
  Number mu_s_column = clamp(floor(mu_s_coord), 0.0, mu_s_size - 2.0);
  x_below = (mu_s_column + 0.5) / mu_s_size;
  x_above = (mu_s_column + 1.5) / mu_s_size;
  low_sun_below = x_below < x_low_sun;
  mu_s_t = SunCosinePosition(mu_s_coord - mu_s_column, low_sun_below);
}

// The blend along mu_s of a low sun at t between texel columns b and c,
// from the light at the four columns a, b, c, d around it: a cubic in ln L
// (Hermite, each end's slope the harmonic mean of the secants beside it,
// 0 where they differ in sign: Fritsch & Butland 1984). After sunset the
// fall of ln L steepens as the sun sinks, and the geometric blend of b and
// c (the chord of ln L) reads it low at mid-column; the cubic follows the
// curve, and being monotone it stays within [b, c] where the light falls
// off a cliff (next to a column whose ray lies in the Earth's shadow).
// has_a, has_d: whether a and d exist; past the table's first or last
// column ln L goes on linearly. Where one of the four is dark, the
// geometric blend (SunCosineMix).
vec4 LogMonotoneCubicMix(vec4 a, vec4 b, vec4 c, vec4 d, bool has_a, bool has_d, Number t) {
  vec4 dark = vec4(1e-30);
  vec4 lb = log(max(b, dark));
  vec4 lc = log(max(c, dark));
  vec4 la = has_a ? log(max(a, dark)) : 2.0 * lb - lc;
  vec4 ld = has_d ? log(max(d, dark)) : 2.0 * lc - lb;
  vec4 secant_a = lb - la;
  vec4 secant = lc - lb;
  vec4 secant_d = ld - lc;
  vec4 product_b = secant_a * secant;
  vec4 product_c = secant * secant_d;
  // 1 where the two secants beside an end agree in sign (the divisor is
  // then not 0; elsewhere it is replaced by 1 and the slope is 0).
  vec4 agree_b = vec4(1.0) - step(product_b, vec4(0.0));
  vec4 agree_c = vec4(1.0) - step(product_c, vec4(0.0));
  vec4 slope_b = agree_b * 2.0 * product_b / mix(vec4(1.0), secant_a + secant, agree_b);
  vec4 slope_c = agree_c * 2.0 * product_c / mix(vec4(1.0), secant + secant_d, agree_c);
  Number t2 = t * t;
  Number t3 = t2 * t;
  vec4 cubic = (2.0 * t3 - 3.0 * t2 + 1.0) * lb + (t3 - 2.0 * t2 + t) * slope_b + (3.0 * t2 - 2.0 * t3) * lc +
               (t3 - t2) * slope_c;
  vec4 lit = step(dark, min(min(a, b), min(c, d)));
  return exp(mix(mix(lb, lc, t), cubic, lit)) * step(dark, max(b, c));
}

// Below the table's lowest sun, ln L continued from the two lowest mu_s
// columns a and b (at sun cosines mu_s_a < mu_s_b): ln L = ln a + slope d +
// curvature d^2 at d = mu_s - mu_s_a < 0. Where both are below the horizon,
// the parabola in mu_s through them with its vertex at the horizon, ln L =
// ln a - k (mu_s^2 - mu_s_a^2): after sunset the light comes from above the
// Earth's shadow, whose height grows as the square of the sun's depression
// delta (h = R delta^2 / 2 about, and -mu_s = sin delta), and falls about as
// exp(-h / H). Else the line through a and b. Where L does not rise from a
// to b (or a is dark), held at a. The bake's gather continues J below its
// grid's lowest sun the same way.
void LowestSunLogFall(IN(vec4) a, IN(vec4) b, Number mu_s_a, Number mu_s_b, OUT(vec4) slope,
                      OUT(vec4) curvature) {
  vec4 dark = vec4(1e-30);
  vec4 rise = (log(max(b, dark)) - log(max(a, dark))) * step(dark, a) * (vec4(1.0) - step(b, a));
  if (mu_s_b < 0.0) {
    vec4 k = rise / (mu_s_a * mu_s_a - mu_s_b * mu_s_b);
    slope = -2.0 * mu_s_a * k;
    curvature = -k;
  } else {
    slope = rise / (mu_s_b - mu_s_a);
    curvature = vec4(0.0);
  }
}

// a, the light at a column at sun cosine mu_s_a, continued to mu_s below
// it as LowestSunLogFall of a and b (at mu_s_b) has ln L fall.
vec4 LowestSunContinued(IN(vec4) a, IN(vec4) b, Number mu_s_a, Number mu_s_b, Number mu_s) {
  vec4 slope;
  vec4 curvature;
  LowestSunLogFall(a, b, mu_s_a, mu_s_b, slope, curvature);
  Number d = mu_s - mu_s_a;
  return a * exp(d * (slope + d * curvature));
}

// The light of nu slice nu_slice at the mu_s texel column at texture
// coordinate x, bilinear in (mu, r) by the texture unit.
vec4 GetScatteringInSlice(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                          IN(vec4) uvwz, Number x, Number nu_slice) {
  return SampleTexture3D(scattering_texture,
                         vec3((nu_slice + x) / Number(atmosphere.scattering_nu_size), uvwz.z, uvwz.w));
}

// The light at the mu_s texel column at texture coordinate x: the two nu
// slices either side of nu blended by SunCosineMix.
vec4 GetScatteringAtMuSColumn(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                              IN(vec4) uvwz, Number x, Number nu_slice, Number nu_t, bool low_sun) {
  return SunCosineMix(GetScatteringInSlice(atmosphere, scattering_texture, uvwz, x, nu_slice),
                      GetScatteringInSlice(atmosphere, scattering_texture, uvwz, x, nu_slice + 1.0), nu_t, low_sun);
}

// The light of one nu slice at a ray's own column (below the split).
vec4 GetScatteringAtOwnColumn(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                              IN(vec4) uvwz, Number column, Number nu_slice) {
  return GetScatteringInSlice(atmosphere, scattering_texture, uvwz,
                              (column + 0.5) / Number(atmosphere.scattering_mu_s_size), nu_slice);
}

// The light of one nu slice below the split at `position` on the ray's
// own columns (GetScatteringShadowEdgePosition): between its lit columns
// LogMonotoneCubicMix of the four around it (the split's column the last);
// within SHADOW_EDGE_CLOSEST of the edge, the light at the edge plus the
// rise to the first lit column times (D / D_min)^p, p from the rise to the
// second (where both rise, in [1, 10]; else 3, the fall of the light next
// to the edge), log_first_span = ln(D_1 / D_min) with D_1 the second lit
// column's distance to the edge; past the edge SunCosineMix of the two
// columns around it.
vec4 GetScatteringBelowSplit(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                             IN(vec4) uvwz, Number position, Number nu_slice, Number log_first_span) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  Number intervals = Number(atmosphere.scattering_mu_s_split) - past;
  if (position >= past) {
    Number k = min(floor(position - past), intervals - 1.0);
    Number column = past + k;
    return LogMonotoneCubicMix(
        GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column - 1.0, nu_slice),
        GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column, nu_slice),
        GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column + 1.0, nu_slice),
        GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, min(column + 2.0, past + intervals), nu_slice),
        k >= 1.0, k + 2.0 <= intervals, position - column);
  }
  if (position >= past - 1.0) {
    vec4 at_edge = GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past - 1.0, nu_slice);
    vec4 rise = GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past, nu_slice) - at_edge;
    vec4 second_rise = GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past + 1.0, nu_slice) - at_edge;
    vec4 tiny = vec4(1e-30);
    vec4 rises = step(tiny, rise) * (vec4(1.0) - step(second_rise, rise));
    vec4 power = mix(vec4(3.0),
                     clamp(log(max(second_rise, tiny) / max(rise, tiny)) / log_first_span, vec4(1.0), vec4(10.0)),
                     rises);
    return at_edge + rise * pow(vec4(position - past + 1.0), power);
  }
  Number x = past - 1.0 - position;
  Number k = min(floor(x), past - 2.0);
  return SunCosineMix(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past - 1.0 - k, nu_slice),
                      GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past - 2.0 - k, nu_slice),
                      x - k, true);
}

// 4D lookup: the mu_s texel columns either side of mu_s
// (GetScatteringAtMuSColumn, two fetches each), blended linearly in
// daylight by the texture unit (two fetches); for a low sun between two columns by
// LogMonotoneCubicMix of the four columns around it (eight fetches), and
// below the table's lowest sun by LowestSunLogFall of the two lowest
// columns (four fetches). Below the split, each nu slice's light on the
// ray's own columns (GetScatteringBelowSplit, up to four fetches each),
// geometric between the two slices, and past the ray's first column
// LowestSunLogFall of its first two (four fetches).
vec4 GetScattering(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                   Number r, Number mu, Number mu_s, Number nu, bool ray_r_mu_intersects_ground) {
  vec2 edge;
  vec4 uvwz = GetScatteringTextureUvwzAndEdge(atmosphere, r, mu, mu_s, nu, ray_r_mu_intersects_ground, edge);
  Number nu_size = Number(atmosphere.scattering_nu_size);
  Number nu_coord = uvwz.x * (nu_size - 1.0);
  Number nu_slice = min(floor(nu_coord), nu_size - 2.0);
  Number nu_t = nu_coord - nu_slice;
  Number mu_s_size = Number(atmosphere.scattering_mu_s_size);
  Number position = uvwz.y * mu_s_size - 0.5;
  if (atmosphere.scattering_mu_s_split > 0 && position < Number(atmosphere.scattering_mu_s_split)) {
    Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
    Number log_first_span = 1.0;
    if (position < past) {
      if (position < 0.0) {
        // Past the first column (the tables' lowest sun, or
        // SHADOW_EDGE_LEAST_PAST_SPAN past the edge): ln L continued from
        // the first two (LowestSunLogFall), as below the tables' lowest sun.
        Number step = ShadowEdgePastStep(atmosphere, edge);
        return LowestSunContinued(
            GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, 0.5 / mu_s_size, nu_slice, nu_t, true),
            GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, 1.5 / mu_s_size, nu_slice, nu_t, true),
            ShadowEdgeSunCosine(edge, -(past - 1.0) * step), ShadowEdgeSunCosine(edge, -(past - 2.0) * step), mu_s);
      }
      if (position >= past - 1.0) {
        Number x = 1.0 / (Number(atmosphere.scattering_mu_s_split) - past);
        log_first_span = log(ShadowEdgeLitDistance(atmosphere, x, edge) / SHADOW_EDGE_CLOSEST);
      }
    }
    return SunCosineMix(
        GetScatteringBelowSplit(atmosphere, scattering_texture, uvwz, position, nu_slice, log_first_span),
        GetScatteringBelowSplit(atmosphere, scattering_texture, uvwz, position, nu_slice + 1.0, log_first_span),
        nu_t, true);
  }
  Number x_below;
  Number x_above;
  Number mu_s_t;
  bool low_sun_below;
  Number x_low_sun = GetScatteringTextureUMuS(atmosphere, LOW_SUN_MU_S);
  GetScatteringMuSColumns(atmosphere, uvwz.y, x_low_sun, x_below, x_above, mu_s_t, low_sun_below);
  if (!low_sun_below) {
    // Daylight: linear along mu_s, which the texture unit does within a nu
    // slice, so one fetch at mu_s_t between the two columns reads their blend.
    return GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, mix(x_below, x_above, mu_s_t), nu_slice,
                                    nu_t, false);
  }
  vec4 below = GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, x_below, nu_slice, nu_t, true);
  vec4 above =
      GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, x_above, nu_slice, nu_t, x_above < x_low_sun);
  if (mu_s_t < 0.0) {
    return LowestSunContinued(below, above, atmosphere.scattering_mu_s_min,
                              GetScatteringMuSFromUnitRange(atmosphere, 1.0 / (mu_s_size - 1.0)), mu_s);
  }
  Number column = x_below * mu_s_size - 0.5;
  Number x_first = (max(column - 1.0, 0.0) + 0.5) / mu_s_size;
  Number x_last = (min(column + 2.0, mu_s_size - 1.0) + 0.5) / mu_s_size;
  vec4 first = GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, x_first, nu_slice, nu_t, true);
  vec4 last =
      GetScatteringAtMuSColumn(atmosphere, scattering_texture, uvwz, x_last, nu_slice, nu_t, x_last < x_low_sun);
  return LogMonotoneCubicMix(first, below, above, last, column > 0.5, column + 2.0 < mu_s_size - 0.5, mu_s_t);
}
#endif

#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
// Bilinear in r by the texture unit at the two mu_s texel columns either
// side of mu_s, then SunBelowTableMix along mu_s: two fetches.
vec3 GetIrradiance(IN(AtmosphereParameters) atmosphere, IN(IrradianceTexture) irradiance_texture,
                   Number r, Number mu_s) {
  vec2 uv = GetIrradianceTextureUvFromRMuS(atmosphere, r, mu_s);
  Number width = Number(atmosphere.irradiance_width);
  Number mu_s_coord = GetIrradianceUnitMuS(atmosphere, mu_s) * (width - 1.0);
  Number mu_s_column = clamp(floor(mu_s_coord), 0.0, width - 2.0);
  Number mu_s_below = GetIrradianceMuSFromUnit(atmosphere, mu_s_column / (width - 1.0));
  bool low_sun = mu_s_below < LOW_SUN_MU_S;
  vec4 below = SampleTexture2D(irradiance_texture, vec2((mu_s_column + 0.5) / width, uv.y));
  vec4 above = SampleTexture2D(irradiance_texture, vec2((mu_s_column + 1.5) / width, uv.y));
  return vec3(SunBelowTableMix(below, above, SunCosinePosition(mu_s_coord - mu_s_column, low_sun), low_sun));
}
#endif

#if SKYBAKE_HAS_SCATTERING_TEXTURE
// ---------------------------------------------------------------------------
// Phase functions (phase_functions.glsl), per steradian.

Number MiePhaseFunction(IN(AtmosphereParameters) atmosphere, Number nu) {
  if (atmosphere.mie_phase == PHASE_HENYEY_GREENSTEIN) return HenyeyGreensteinPhaseFunction(atmosphere.mie_g, nu);
  if (atmosphere.mie_phase == PHASE_CORNETTE_SHANKS) return CornetteShanksPhaseFunction(atmosphere.mie_g, nu);
  return 0.0;
}

// ---------------------------------------------------------------------------
// Run-time functions.

// Scattering-table radiance (divided by the Rayleigh phase function) and
// single Mie radiance (phase free) along the ray (r, mu) for the sun at (mu_s, nu).
vec3 GetCombinedScattering(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                           IN(ScatteringTexture) single_mie_scattering_texture, Number r, Number mu,
                           Number mu_s, Number nu, bool ray_r_mu_intersects_ground,
                           OUT(vec3) single_mie_scattering) {
  vec4 scattering = GetScattering(atmosphere, scattering_texture, r, mu, mu_s, nu, ray_r_mu_intersects_ground);
  if (atmosphere.single_mie_in_scattering_alpha == 1) {
    // Only the red channel of single Mie was stored; rebuild the others from the
    // main table's colour (Bruneton 2017, Section "Combined scattering").
    single_mie_scattering = scattering.r > 0.0
        ? vec3(scattering) * scattering.a / scattering.r * (atmosphere.mie_to_rayleigh_scattering_ratio /
                                                             atmosphere.mie_to_rayleigh_scattering_ratio.r)
        : vec3(0.0);
  } else {
    single_mie_scattering = vec3(GetScattering(atmosphere, single_mie_scattering_texture, r, mu, mu_s, nu,
                                               ray_r_mu_intersects_ground));
  }
  return vec3(scattering);
}

// The sky radiance along the ray (r, mu) to where it leaves the atmosphere
// or meets the ground, for the sun at (mu_s, nu): the tables' light times
// the phase functions.
vec3 GetSkyRadianceOfRay(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                         IN(ScatteringTexture) single_mie_scattering_texture, Number r, Number mu, Number mu_s,
                         Number nu, bool ray_r_mu_intersects_ground) {
  vec3 single_mie_scattering;
  vec3 scattering = GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r, mu,
                                          mu_s, nu, ray_r_mu_intersects_ground, single_mie_scattering);
  return scattering * RayleighPhaseFunction(nu) + single_mie_scattering * MiePhaseFunction(atmosphere, nu);
}

// Sky radiance seen from `camera` along the unit vector `view_ray`, without
// the sun disc and without ground reflection, and the transmittance to the
// top of the atmosphere (0 if the ray hits the ground). A camera in space is
// moved to where the ray enters the atmosphere.
vec3 GetSkyRadiance(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                    IN(ScatteringTexture) scattering_texture, IN(ScatteringTexture) single_mie_scattering_texture,
                    IN(vec3) camera, IN(vec3) view_ray, IN(vec3) sun_direction, OUT(vec3) transmittance) {
  vec3 start;
  Number r;
  Number mu;
  Number mu_s;
  Number nu;
  if (!GetViewRayStart(atmosphere, camera, view_ray, sun_direction, start, r, mu, mu_s, nu)) {
    transmittance = vec3(1.0);
    return vec3(0.0);
  }
  bool ray_r_mu_intersects_ground = RayIntersectsGround(atmosphere, r, mu);
  transmittance = ray_r_mu_intersects_ground
      ? vec3(0.0)
      : GetTransmittanceToTopAtmosphereBoundary(atmosphere, transmittance_texture, r, mu);
  return GetSkyRadianceOfRay(atmosphere, scattering_texture, single_mie_scattering_texture, r, mu, mu_s, nu,
                             ray_r_mu_intersects_ground);
}
#endif

