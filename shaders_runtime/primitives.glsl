// skybake GLSL runtime: scalar primitives. Written on numbers only (no
// AtmosphereParameters, no textures), so that besides the engine's GLSL and
// the double-precision C++ twin, the bake's vectorised loops compile this same
// text with Number = float (shaders_runtime/primitives.h) instead of keeping
// float copies of the formulas. Every literal is written Number(...): in the
// float instantiation a bare 1.0 is a double and would pull a float loop into
// double arithmetic.

// ---------------------------------------------------------------------------
// Defensive numerics

Number ClampCosine(Number mu) {
  return clamp(mu, Number(-1.0), Number(1.0));
}

Number ClampDistance(Number d) {
  return max(d, Number(0.0));
}

Number SafeSqrt(Number a) {
  return sqrt(max(a, Number(0.0)));
}

// ---------------------------------------------------------------------------
// Sphere geometry

// Distance from a point inside a sphere (or on it) to the sphere along a ray,
// given r_mu = r mu (r the point's radius, mu the ray's direction cosine) and
// c = R^2 - r^2 >= 0 (R the sphere's radius): the positive root of
// d^2 + 2 r_mu d - c = 0. Of -r_mu + sqrt(r_mu^2 + c), the form that would
// subtract nearly equal numbers (r_mu > 0) is written c / (r_mu + sqrt(...)):
// it stays accurate for rays that start a millimetre below the sphere.
Number DistanceToSphereFromInside(Number r_mu, Number c) {
  Number s = SafeSqrt(r_mu * r_mu + c);
  return ClampDistance(r_mu > Number(0.0) ? c / (r_mu + s) : s - r_mu);
}

// Distance from radius r >= bottom_radius to its horizon on the sphere of
// radius bottom_radius: sqrt(r^2 - bottom^2), 0 on the ground.
Number DistanceToHorizon(Number bottom_radius, Number r) {
  return SafeSqrt((r - bottom_radius) * (r + bottom_radius));
}

// The height above the ground of the point whose distance to the horizon is
// rho (the inverse of DistanceToHorizon): rho^2 / (r + bottom_radius) with
// r = sqrt(rho^2 + bottom_radius^2), free of the cancellation of r - bottom.
Number HeightFromHorizonDistance(Number bottom_radius, Number rho) {
  return rho * rho / (sqrt(rho * rho + bottom_radius * bottom_radius) + bottom_radius);
}

// Cosine of the zenith angle of the geometric horizon seen from radius
// r >= bottom_radius: -sqrt(r^2 - bottom^2) / r, written through the distance
// to the horizon rather than as -sqrt(1 - (bottom / r)^2), whose 1 - ... loses
// the digits of a camera near the ground (in float at 1 m above the Earth the
// latter is off by 1e-4, a fifth of the sun's disc).
Number HorizonZenithCosine(Number bottom_radius, Number r) {
  return -DistanceToHorizon(bottom_radius, r) / r;
}

// Fraction of the sun's disc above the horizon, for the sun's zenith cosine
// mu_s, the horizon's horizon_cosine and the disc's half extent half_disc in
// cosine (sin_horizon times the sun's angular radius): a smooth step across
// the disc (Bruneton 2017).
Number SunVisibleFractionAboveHorizon(Number mu_s, Number horizon_cosine, Number half_disc) {
  return smoothstep(-half_disc, half_disc, mu_s - horizon_cosine);
}

// ---------------------------------------------------------------------------
// Table coordinates

// The scattering table's unit mu_s before its stretch to scattering_mu_s_max,
// from a = (d - d_min) / (d_max - d_min), the sun ray's distance d to the top
// from the ground over its range, and inverse_A = 1 / A, A the same for
// scattering_mu_s_min: (1 - a / A) / (1 + k a), k =
// SCATTERING_MU_S_HIGH_SUN_SHARE, which gives low suns (a near A) more
// texels, and is negative below scattering_mu_s_min, where the lookups
// extrapolate. (1 / A is a constant of the table, computed once.) The
// smaller k, the more of the texels go to the low sun: on Earth (sun down
// to 102 degrees, 32 texels) k = 1 (Bruneton's mapping) puts 11.1 of the 31
// intervals below the horizon, k = 1/2 14.7 (and the sun from the zenith to
// 51 degrees in the last one, where the sky changes slowly with it; see
// docs/accuracy.md, "Twilight: more mu_s texels after sunset").
const Number SCATTERING_MU_S_HIGH_SUN_SHARE = 0.5;

Number ScatteringUnitMuSFromDistance(Number a, Number inverse_A) {
  return (Number(1.0) - a * inverse_A) / (Number(1.0) + SCATTERING_MU_S_HIGH_SUN_SHARE * a);
}

// Its inverse: a from the unit mu_s x, a = (1 - x) / (k x + 1 / A).
Number ScatteringDistanceFromUnitMuS(Number x, Number inverse_A) {
  return (Number(1.0) - x) / (SCATTERING_MU_S_HIGH_SUN_SHARE * x + inverse_A);
}

// The scattering table's unit nu: (nu + 1) / 2 over the slices.
Number ScatteringUnitNu(Number nu) {
  return (nu + Number(1.0)) / Number(2.0);
}
