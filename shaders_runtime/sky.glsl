// skybake GLSL runtime: the sky's entry points (after lookups.glsl; aerial
// perspective and irradiance follow in aerial_perspective.glsl).

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
  ScatteringLookup lookup = GetScatteringLookup(atmosphere, r, mu, mu_s, nu, ray_r_mu_intersects_ground);
  vec4 scattering = GetScatteringFromLookup(atmosphere, scattering_texture, lookup);
  if (atmosphere.single_mie_in_scattering_alpha == 1) {
    // Only the red channel of single Mie was stored; rebuild the others from the
    // main table's colour (Bruneton 2017, Section "Combined scattering").
    single_mie_scattering = scattering.r > 0.0
        ? vec3(scattering) * scattering.a / scattering.r * (atmosphere.mie_to_rayleigh_scattering_ratio /
                                                             atmosphere.mie_to_rayleigh_scattering_ratio.r)
        : vec3(0.0);
  } else {
    single_mie_scattering = vec3(GetScatteringFromLookup(atmosphere, single_mie_scattering_texture, lookup));
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

