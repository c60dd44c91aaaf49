// skybake GLSL runtime: the scattering table's view zenith (mu) and sun
// (mu_s) axes, and the irradiance table's coordinates (after geometry.glsl).

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

// The constants of the scattering table's mu_s axis, found once per lookup:
// H (HorizonDistanceAtTop), A of ScatteringUnitMuSFromDistance (the
// distance to the top boundary from the ground for the sun at
// scattering_mu_s_min, over its range from d_min = top - bottom, the sun at
// the zenith, to d_max = H) and 1 / A, and the unit mu_s of
// scattering_mu_s_max (GetScatteringUnitMuSOnAxis), which maps to 1.
struct ScatteringSunAxis {
  Number H;
  Number A;
  Number inverse_A;
  Number unit_max;
};

// mu_s through the distance to the top boundary from the ground, rescaled so
// that scattering_mu_s_min maps to 0 and more texels go to low suns (before
// the stretch by unit_max). Independent of r: the bake maps the sun's cosine
// along a ray with it alone. Reads the axis's H and inverse_A only.
Number GetScatteringUnitMuSOnAxis(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) axis, Number mu_s) {
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, atmosphere.bottom_radius, mu_s);
  Number d_min = atmosphere.top_radius - atmosphere.bottom_radius;
  Number a = (d - d_min) / (axis.H - d_min);
  return ScatteringUnitMuSFromDistance(a, axis.inverse_A);
}

ScatteringSunAxis GetScatteringSunAxis(IN(AtmosphereParameters) atmosphere) {
  ScatteringSunAxis axis;
  Number d_min = atmosphere.top_radius - atmosphere.bottom_radius;
  axis.H = HorizonDistanceAtTop(atmosphere);
  Number D = DistanceToTopAtmosphereBoundary(atmosphere, atmosphere.bottom_radius, atmosphere.scattering_mu_s_min);
  axis.A = (D - d_min) / (axis.H - d_min);
  axis.inverse_A = 1.0 / axis.A;
  axis.unit_max = 0.0;
  axis.unit_max = GetScatteringUnitMuSOnAxis(atmosphere, axis, atmosphere.scattering_mu_s_max);
  return axis;
}

Number GetScatteringUnitMuS(IN(AtmosphereParameters) atmosphere, Number mu_s) {
  return GetScatteringUnitMuSOnAxis(atmosphere, GetScatteringSunAxis(atmosphere), mu_s);
}

// The inverse of the unit mu_s stretched to [0, 1]: the sun cosine at x in
// [0, 1] along the table's mu_s axis (x = column / (size - 1) at a texel
// column): a by ScatteringDistanceFromUnitMuS, then d, and mu_s from
// top^2 = bottom^2 + 2 bottom mu_s d + d^2.
Number GetScatteringMuSFromUnitRangeOnAxis(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) axis,
                                           Number x) {
  Number bottom = atmosphere.bottom_radius;
  Number d_min = atmosphere.top_radius - bottom;
  Number a = ScatteringDistanceFromUnitMuS(x * axis.unit_max, axis.inverse_A);
  Number d = d_min + min(a, axis.A) * (axis.H - d_min);
  return d == 0.0 ? 1.0 : ClampCosine((axis.H * axis.H - d * d) / (2.0 * bottom * d));
}

Number GetScatteringMuSFromUnitRange(IN(AtmosphereParameters) atmosphere, Number x) {
  return GetScatteringMuSFromUnitRangeOnAxis(atmosphere, GetScatteringSunAxis(atmosphere), x);
}

// The texture coordinate along mu_s within a nu slice.
Number GetScatteringTextureUMuSOnAxis(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) axis,
                                      Number mu_s) {
  Number x = GetScatteringUnitMuSOnAxis(atmosphere, axis, mu_s) / axis.unit_max;
  return GetTextureCoordFromUnitRange(min(x, 1.0), atmosphere.scattering_mu_s_size);
}

Number GetScatteringTextureUMuS(IN(AtmosphereParameters) atmosphere, Number mu_s) {
  return GetScatteringTextureUMuSOnAxis(atmosphere, GetScatteringSunAxis(atmosphere), mu_s);
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

