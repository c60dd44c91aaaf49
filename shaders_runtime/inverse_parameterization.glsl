// Inverses of the table parameterizations (table_mappings.glsl, lookups.glsl): from a texel's
// texture coordinates back to the physical (r, mu, mu_s, nu) it stands for.
// The bake evaluates these at texel centres; engines never need them, so this
// file is not part of the shipped snippet. Round trips are tested.

void GetRMuFromTransmittanceTextureUv(IN(AtmosphereParameters) atmosphere, IN(vec2) uv, OUT(Number) r,
                                      OUT(Number) mu) {
  Number x_mu = GetUnitRangeFromTextureCoord(uv.x, atmosphere.transmittance_width);
  Number x_r = GetUnitRangeFromTextureCoord(uv.y, atmosphere.transmittance_height);
  Number H = HorizonDistanceAtTop(atmosphere);
  Number rho = H * x_r;
  r = sqrt(rho * rho + atmosphere.bottom_radius * atmosphere.bottom_radius);
  Number d_min = atmosphere.top_radius - r;
  Number d_max = rho + H;
  Number d = d_min + x_mu * (d_max - d_min);
  // top^2 = r^2 + 2 r mu d + d^2, with top^2 - r^2 = H^2 - rho^2.
  mu = d == 0.0 ? 1.0 : ClampCosine((H * H - rho * rho - d * d) / (2.0 * r * d));
}

// nu clamped to the range that the view and sun zenith cosines allow:
// nu = mu mu_s + sqrt((1 - mu^2)(1 - mu_s^2)) cos(azimuth), azimuth in [0, pi].
Number ClampNuToDirections(Number nu, Number mu, Number mu_s) {
  Number spread = SafeSqrt((1.0 - mu * mu) * (1.0 - mu_s * mu_s));
  return clamp(nu, mu * mu_s - spread, mu * mu_s + spread);
}

// The shadow edge (ShadowEdgeSunZenith) of the ray (r, mu) for the sun at
// zenith cosine mu_s in the direction of the nu slice at nu: at the azimuth
// where nu, clamped to the range mu and mu_s allow, lies.
Number GetScatteringSliceEdge(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number nu,
                              bool ray_r_mu_intersects_ground, Number mu_s) {
  Number cos_phi = ViewSunAzimuthCosine(mu, mu_s, ClampNuToDirections(nu, mu, mu_s));
  return ShadowEdgeSunZenith(atmosphere, r, mu, cos_phi, ray_r_mu_intersects_ground);
}

// The sun zenith angle of a ray's own column at `position` below the split
// (E - GetScatteringShadowEdgeDistance) for the nu slice at nu: the
// column's sun sets the azimuth at which nu lies, which sets the ray's edge
// (GetScatteringSliceEdge), which sets the column's sun. Their fixed
// point, from the edge start_edge (the edge moves less than the sun does:
// on Earth's default table three steps from the edge of a sun at the
// horizon, on average, to 1e-11 radians); `edge` is the column's.
Number GetScatteringOwnColumnSunZenith(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number nu,
                                       bool ray_r_mu_intersects_ground, Number position, Number start_edge,
                                       OUT(Number) edge) {
  ScatteringSunAxis sun_axis = GetScatteringSunAxis(atmosphere);
  edge = start_edge;
  Number sun = edge - GetScatteringShadowEdgeDistance(atmosphere, sun_axis, position, ShadowEdgeDirection(edge));
  for (int i = 0; i < 50; ++i) {
    edge = GetScatteringSliceEdge(atmosphere, r, mu, nu, ray_r_mu_intersects_ground, cos(sun));
    Number next =
        edge - GetScatteringShadowEdgeDistance(atmosphere, sun_axis, position, ShadowEdgeDirection(edge));
    bool converged = abs(next - sun) < 1e-11;
    sun = next;
    if (converged) break;
  }
  return sun;
}

// uvwz = (u_nu, u_mu_s, u_mu, u_r) as returned by
// GetScatteringTextureUvwzFromRMuMuSNu. nu is not clamped to the range that
// (mu, mu_s) allow; callers that need a physical direction clamp it.
void GetRMuMuSNuFromScatteringTextureUvwz(IN(AtmosphereParameters) atmosphere, IN(vec4) uvwz, OUT(Number) r,
                                          OUT(Number) mu, OUT(Number) mu_s, OUT(Number) nu,
                                          OUT(bool) ray_r_mu_intersects_ground) {
  Number rho_min = HorizonDistance(atmosphere, atmosphere.scattering_r_min);
  Number rho_max = HorizonDistance(atmosphere, atmosphere.scattering_r_max);
  Number rho = rho_min + (rho_max - rho_min) * GetUnitRangeFromTextureCoord(uvwz.w, atmosphere.scattering_r_size);
  Number bottom = atmosphere.bottom_radius;
  r = sqrt(rho * rho + bottom * bottom);

  Number x_mu = GetUnitMuInHalfFromTextureCoord(uvwz.z, atmosphere.scattering_mu_size, ray_r_mu_intersects_ground);
  mu = GetMuFromUnitMuInHalf(atmosphere, r, rho, x_mu, ray_r_mu_intersects_ground);

  nu = ClampCosine(uvwz.x * 2.0 - 1.0);
  Number x_mu_s = GetUnitRangeFromTextureCoord(uvwz.y, atmosphere.scattering_mu_s_size);
  Number position = x_mu_s * Number(atmosphere.scattering_mu_s_size - 1);
  mu_s = GetScatteringMuSFromUnitRange(atmosphere, x_mu_s);
  if (atmosphere.scattering_mu_s_split > 0 && position < Number(atmosphere.scattering_mu_s_split)) {
    Number edge;
    mu_s = cos(GetScatteringOwnColumnSunZenith(
        atmosphere, r, mu, nu, ray_r_mu_intersects_ground, position,
        GetScatteringSliceEdge(atmosphere, r, mu, nu, ray_r_mu_intersects_ground, 0.0), edge));
  }
}

void GetRMuSFromIrradianceTextureUv(IN(AtmosphereParameters) atmosphere, IN(vec2) uv, OUT(Number) r,
                                    OUT(Number) mu_s) {
  Number x_mu_s = GetUnitRangeFromTextureCoord(uv.x, atmosphere.irradiance_width);
  Number x_r = GetUnitRangeFromTextureCoord(uv.y, atmosphere.irradiance_height);
  Number rho = HorizonDistanceAtTop(atmosphere) * x_r;
  r = sqrt(rho * rho + atmosphere.bottom_radius * atmosphere.bottom_radius);
  mu_s = ClampCosine(GetIrradianceMuSFromUnit(atmosphere, x_mu_s));
}

// The texture coordinates uvwz of texel (x, y, z) of a scattering table as
// GetScattering reads it: x = nu index * mu_s size + mu_s index; texel centres
// on the mu_s, mu and r axes, and on the nu axis the slice's own coordinate
// index / (nu size - 1), at which GetScattering reads that slice alone.
vec4 GetScatteringTextureUvwzFromTexel(IN(AtmosphereParameters) atmosphere, int x, int y, int z) {
  int mu_s_size = atmosphere.scattering_mu_s_size;
  int nu_index = x / mu_s_size;
  int mu_s_index = x - nu_index * mu_s_size;
  return vec4(Number(nu_index) / Number(atmosphere.scattering_nu_size - 1),
              (Number(mu_s_index) + 0.5) / Number(mu_s_size),
              (Number(y) + 0.5) / Number(atmosphere.scattering_mu_size),
              (Number(z) + 0.5) / Number(atmosphere.scattering_r_size));
}
