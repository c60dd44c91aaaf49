#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
// ---------------------------------------------------------------------------
// Aerial perspective.
//
// The table method, S(camera) - T S(point) with T from two optical-depth
// lookups, subtracts nearly equal numbers when the segment is short, most of
// all near the horizon and the ground where the tables vary fastest: before
// the change below it was off by up to 85% for a 100 m segment at view zenith
// 85 degrees on the ground, and its transmittance by 1.7e-3
// (shaders_runtime/README.md). So a segment shorter than
// DIRECT_SEGMENT_LENGTH is integrated along itself instead, with the
// coefficient profiles of definitions.glsl:
// - transmittance and single scattering (Rayleigh and Mie) directly;
// - multiple scattering, which the scattering table holds together with
//   single Rayleigh, by the table method over a segment of
//   DIRECT_SEGMENT_LENGTH (long enough not to cancel) minus its direct single
//   Rayleigh, scaled to the short segment by the ratio of
//   integral T sigma_s dt over the two: multiply scattered light varies
//   slowly over such distances, so what it adds to a segment follows the
//   amount of scattering along it.
// Between one and two DIRECT_SEGMENT_LENGTHs the table method is used with
// the transmittance and single Mie blended from the direct integration to
// the tables, so the result is continuous in the distance.

// Metres.
const Number DIRECT_SEGMENT_LENGTH = 10000.0;

// Distance along the ray (r, mu), from r inside the radii the scattering
// tables cover, to where it leaves them (a scene's bake restricts them; over
// the whole atmosphere this is the nearest boundary or beyond).
Number DistanceInsideScatteringRadii(IN(AtmosphereParameters) atmosphere, Number r, Number mu) {
  Number r_max = atmosphere.scattering_r_max;
  Number r_min = atmosphere.scattering_r_min;
  Number across = r * r * (mu * mu - 1.0);
  Number up = -r * mu + SafeSqrt(across + r_max * r_max);
  Number down_discriminant = across + r_min * r_min;
  return mu < 0.0 && down_discriminant >= 0.0 ? min(up, -r * mu - sqrt(down_discriminant)) : up;
}

// Trapezoidal intervals of the direct integration. On Earth the rule
// overestimates the optical depth (440 nm) of a vertical segment from the
// ground by 4.5e-5 at 5 km and 2.2e-4 at 10 km (the aerosols' 1.2 km scale
// height), and of near-horizontal segments, whose altitude changes slowly,
// by far less.
const int SEGMENT_INTERVALS = 16;

Number ProfileSampleAltitude(IN(AtmosphereParameters) atmosphere, int i) {
  Number x = Number(i) / Number(ALTITUDE_PROFILE_SIZE - 1);
  return (atmosphere.top_radius - atmosphere.bottom_radius) * x * x;
}

// Log-linear between two profile samples: exact for an exponential density,
// linear where a sample is 0 (a layer that ends).
Number InterpolateCoefficient(Number a, Number b, Number f) {
  return a > 0.0 && b > 0.0 ? a * exp(f * log(b / a)) : mix(a, b, f);
}

vec3 InterpolateCoefficients(vec3 a, vec3 b, Number f) {
  return vec3(InterpolateCoefficient(a.x, b.x, f), InterpolateCoefficient(a.y, b.y, f),
              InterpolateCoefficient(a.z, b.z, f));
}

// Extinction at `altitude` above the ground, and the scattering of the Mie
// group and of the other groups there.
vec3 GetCoefficientsAtAltitude(IN(AtmosphereParameters) atmosphere, Number altitude, OUT(vec3) mie_scattering,
                               OUT(vec3) rayleigh_scattering) {
  Number height = atmosphere.top_radius - atmosphere.bottom_radius;
  Number x = sqrt(clamp(altitude / height, 0.0, 1.0)) * Number(ALTITUDE_PROFILE_SIZE - 1);
  int i = min(int(x), ALTITUDE_PROFILE_SIZE - 2);
  Number h0 = ProfileSampleAltitude(atmosphere, i);
  Number f = clamp((altitude - h0) / (ProfileSampleAltitude(atmosphere, i + 1) - h0), 0.0, 1.0);
  mie_scattering = InterpolateCoefficients(atmosphere.mie_scattering_profile[i],
                                           atmosphere.mie_scattering_profile[i + 1], f);
  rayleigh_scattering = InterpolateCoefficients(atmosphere.rayleigh_scattering_profile[i],
                                                atmosphere.rayleigh_scattering_profile[i + 1], f);
  return InterpolateCoefficients(atmosphere.extinction_profile[i], atmosphere.extinction_profile[i + 1], f);
}

// The altitude at distance t along the ray (r, mu), whose radius there is
// r_t: the start's plus the rise along the ray, so that it does not inherit
// the rounding of a radius near 6.4e6 m in float.
Number AltitudeAtDistance(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number t, Number r_t) {
  return r - atmosphere.bottom_radius + t * (t + 2.0 * r * mu) / (r_t + r);
}

// The optical depth of the segment of length d from radius r in direction
// mu, by the trapezoidal rule on the extinction profile (as IntegrateSegment
// below).
vec3 IntegrateSegmentOpticalDepth(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number d) {
  Number dt = d / Number(SEGMENT_INTERVALS);
  vec3 optical_depth = vec3(0.0);
  vec3 previous_extinction = vec3(0.0);
  for (int k = 0; k <= SEGMENT_INTERVALS; ++k) {
    Number t = dt * Number(k);
    Number r_t = RadiusAtDistance(atmosphere, r, mu, t);
    vec3 mie_scattering;
    vec3 rayleigh_scattering;
    vec3 extinction = GetCoefficientsAtAltitude(atmosphere, AltitudeAtDistance(atmosphere, r, mu, t, r_t),
                                                mie_scattering, rayleigh_scattering);
    if (k > 0) optical_depth += (previous_extinction + extinction) * (0.5 * dt);
    previous_extinction = extinction;
  }
  return optical_depth;
}

// The optical depth of a segment longer than the direct integration covers:
// two lookups of the transmittance table (GetOpticalDepth), exact at one
// wavelength per channel. A colour's optical depths do not add
// (transmittance_is_colour): the difference of the whole rays' optical depths
// of sunlight's colour from the two ends is that of the wavelengths that
// survive the longer ray, too small for the segment (it took 15 to 22 % off
// the aerial perspective over 30 km near the horizon, docs/colour.md), so
// for colour the segment is integrated along itself.
vec3 LongSegmentOpticalDepth(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                             Number r, Number mu, Number d, bool ray_r_mu_intersects_ground) {
  return atmosphere.transmittance_is_colour != 0
             ? IntegrateSegmentOpticalDepth(atmosphere, r, mu, d)
             : GetOpticalDepth(atmosphere, transmittance_texture, r, mu, d, ray_r_mu_intersects_ground);
}

// Along the segment of length d from radius r in direction mu, for the sun
// at (mu_s, nu), by the trapezoidal rule: the optical depth (returned); the
// single scattering of the groups the scattering table holds (divided by the
// Rayleigh phase function, as the table is) and of the Mie group (phase
// free), with sunlight attenuated as in the bake (transmittance table toward
// the sun, fraction of the disc above the horizon); and the scattering
// weight, the integral of T(camera, t) * total scattering coefficient dt.
// The mean of exp(-x) over [0, depth]: (1 - exp(-depth)) / depth, by its
// series where that would cancel.
Number MeanAttenuation(Number depth) {
  return depth < 1e-4 ? 1.0 - 0.5 * depth : (1.0 - exp(-depth)) / depth;
}

vec3 IntegrateSegment(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture, Number r,
                      Number mu, Number mu_s, Number nu, Number d, OUT(vec3) single_rayleigh,
                      OUT(vec3) single_mie, OUT(vec3) scattering_weight) {
  Number dt = d / Number(SEGMENT_INTERVALS);
  vec3 optical_depth = vec3(0.0);
  vec3 previous_extinction = vec3(0.0);
  vec3 previous_rayleigh = vec3(0.0);
  vec3 previous_mie = vec3(0.0);
  vec3 previous_scattering = vec3(0.0);
  single_rayleigh = vec3(0.0);
  single_mie = vec3(0.0);
  scattering_weight = vec3(0.0);
  for (int k = 0; k <= SEGMENT_INTERVALS; ++k) {
    Number t = dt * Number(k);
    Number r_t = RadiusAtDistance(atmosphere, r, mu, t);
    Number altitude = AltitudeAtDistance(atmosphere, r, mu, t, r_t);
    Number mu_s_t = ClampCosine((r * mu_s + t * nu) / r_t);
    vec3 mie_scattering;
    vec3 rayleigh_scattering;
    vec3 extinction = GetCoefficientsAtAltitude(atmosphere, altitude, mie_scattering, rayleigh_scattering);
    vec3 sunlight = exp(-GetOpticalDepthToTopAtmosphereBoundary(atmosphere, transmittance_texture, r_t, mu_s_t)) *
                    SunVisibleFraction(atmosphere, r_t, mu_s_t);
    vec3 rayleigh = rayleigh_scattering * sunlight;
    vec3 mie = mie_scattering * sunlight;
    vec3 scattering = rayleigh_scattering + mie_scattering;
    if (k > 0) {
      // The sources are trapezoidal over the interval, the transmittance to
      // the camera exponential within it: the interval's integral of T is
      // T_start (1 - exp(-dtau)) / dtau, exact in a thick medium (where a
      // trapezoid of T overshoots without bound) and T's trapezoid when thin.
      vec3 interval_depth = (previous_extinction + extinction) * (0.5 * dt);
      vec3 start_transmittance = exp(-optical_depth);
      vec3 mean_transmittance = start_transmittance * vec3(MeanAttenuation(interval_depth.x),
                                                           MeanAttenuation(interval_depth.y),
                                                           MeanAttenuation(interval_depth.z));
      single_rayleigh += (previous_rayleigh + rayleigh) * (0.5 * dt) * mean_transmittance;
      single_mie += (previous_mie + mie) * (0.5 * dt) * mean_transmittance;
      scattering_weight += (previous_scattering + scattering) * (0.5 * dt) * mean_transmittance;
      optical_depth += interval_depth;
    }
    previous_extinction = extinction;
    previous_rayleigh = rayleigh;
    previous_mie = mie;
    previous_scattering = scattering;
  }
  single_rayleigh *= atmosphere.solar_irradiance;
  single_mie *= atmosphere.solar_irradiance;
  return optical_depth;
}

// In-scattered radiance between `camera` and `point` and the transmittance
// between them, for a point whose last `shadow_length` metres toward it lie
// in shadow (light shafts, Bruneton & Neyret 2008 Section 5): light is
// gathered only on the sunlit part next to the camera; as in Bruneton's 2017
// implementation the shadowed part adds no scattering of any order. The
// transmittance is that of the whole segment.
vec3 GetSkyRadianceToPointWithShadow(IN(AtmosphereParameters) atmosphere,
                                     IN(TransmittanceTexture) transmittance_texture,
                                     IN(ScatteringTexture) scattering_texture,
                                     IN(ScatteringTexture) single_mie_scattering_texture, IN(vec3) camera,
                                     IN(vec3) point, Number shadow_length, IN(vec3) sun_direction,
                                     OUT(vec3) transmittance) {
  // A point that coincides with the camera once rounded (a distance below the
  // precision of the positions) has no direction, and nothing lies between.
  vec3 camera_to_point = point - camera;
  if (dot(camera_to_point, camera_to_point) == 0.0) {
    transmittance = vec3(1.0);
    return vec3(0.0);
  }
  vec3 view_ray = normalize(camera_to_point);
  vec3 start;
  Number r;
  Number mu;
  Number mu_s;
  Number nu;
  if (!GetViewRayStart(atmosphere, camera, view_ray, sun_direction, start, r, mu, mu_s, nu)) {
    transmittance = vec3(1.0);
    return vec3(0.0);
  }
  Number d = max(length(point - start), 0.0);
  Number lit = max(d - max(shadow_length, 0.0), 0.0);
  bool ray_r_mu_intersects_ground = RayIntersectsGround(atmosphere, r, mu);

  // The far end of the sunlit part.
  Number r_p = RadiusAtDistance(atmosphere, r, mu, lit);
  Number mu_p = CosineAtDistance(r, mu, lit, r_p);
  Number mu_s_p = ClampCosine((r * mu_s + lit * nu) / r_p);

  // The transmittance of the whole segment: integrated directly, blended
  // into the tables' between one and two DIRECT_SEGMENT_LENGTHs.
  Number direct = 1.0 - smoothstep(DIRECT_SEGMENT_LENGTH, 2.0 * DIRECT_SEGMENT_LENGTH, d);
  Number lit_direct = 1.0 - smoothstep(DIRECT_SEGMENT_LENGTH, 2.0 * DIRECT_SEGMENT_LENGTH, lit);
  vec3 single_rayleigh = vec3(0.0);
  vec3 single_mie = vec3(0.0);
  vec3 lit_weight = vec3(0.0);
  vec3 lit_optical_depth = vec3(0.0);
  if (lit_direct > 0.0) {
    lit_optical_depth = IntegrateSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, lit, single_rayleigh,
                                         single_mie, lit_weight);
  }
  vec3 optical_depth = lit_optical_depth;
  if (direct > 0.0 && lit < d) {
    vec3 unused_rayleigh;
    vec3 unused_mie;
    vec3 unused_weight;
    optical_depth += IntegrateSegment(atmosphere, transmittance_texture, r_p, mu_p, mu_s_p, nu, d - lit,
                                      unused_rayleigh, unused_mie, unused_weight);
  }
  if (direct < 1.0) {
    optical_depth = mix(LongSegmentOpticalDepth(atmosphere, transmittance_texture, r, mu, d,
                                                ray_r_mu_intersects_ground),
                        optical_depth, direct);
  }
  transmittance = exp(-optical_depth);

  // The light gathered depends on the sunlit part alone.
  vec3 single_mie_scattering;
  vec3 scattering = GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r, mu,
                                          mu_s, nu, ray_r_mu_intersects_ground, single_mie_scattering);
  if (lit < DIRECT_SEGMENT_LENGTH) {
    // Multiple scattering by the table method over a segment long enough not
    // to cancel (or up to the ground or the top, where the table alone
    // holds the whole ray), less its single Rayleigh; the far end stays
    // where the tables are.
    Number boundary = DistanceToNearestAtmosphereBoundary(atmosphere, r, mu, ray_r_mu_intersects_ground);
    Number far = max(min(min(DIRECT_SEGMENT_LENGTH, boundary), DistanceInsideScatteringRadii(atmosphere, r, mu)), lit);
    vec3 far_rayleigh;
    vec3 far_mie;
    vec3 far_weight;
    vec3 far_optical_depth = IntegrateSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, far, far_rayleigh,
                                              far_mie, far_weight);
    if (far < boundary) {
      Number r_far = RadiusAtDistance(atmosphere, r, mu, far);
      vec3 unused_far_mie;
      scattering -= exp(-far_optical_depth) *
                    GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r_far,
                                          CosineAtDistance(r, mu, far, r_far), ClampCosine((r * mu_s + far * nu) / r_far),
                                          nu, ray_r_mu_intersects_ground, unused_far_mie);
    }
    vec3 multiple = max(scattering - far_rayleigh, vec3(0.0)) * lit_weight / max(far_weight, vec3(1e-30));
    return (single_rayleigh + multiple) * RayleighPhaseFunction(nu) + single_mie * MiePhaseFunction(atmosphere, nu);
  }
  // A longer sunlit part: the table method, with its transmittance and single
  // Mie blended from the direct integration up to twice DIRECT_SEGMENT_LENGTH.
  vec3 lit_transmittance = exp(-mix(LongSegmentOpticalDepth(atmosphere, transmittance_texture, r, mu, lit,
                                                            ray_r_mu_intersects_ground),
                                    lit_optical_depth, lit_direct));
  vec3 single_mie_scattering_p;
  vec3 scattering_p = GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r_p,
                                            mu_p, mu_s_p, nu, ray_r_mu_intersects_ground,
                                            single_mie_scattering_p);
  scattering = max(scattering - lit_transmittance * scattering_p, vec3(0.0));
  single_mie_scattering = max(single_mie_scattering - lit_transmittance * single_mie_scattering_p, vec3(0.0));
  single_mie_scattering = mix(single_mie_scattering, single_mie, lit_direct);
  return scattering * RayleighPhaseFunction(nu) + single_mie_scattering * MiePhaseFunction(atmosphere, nu);
}

// In-scattered radiance between `camera` and `point` (aerial perspective),
// and the transmittance between them.
vec3 GetSkyRadianceToPoint(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                           IN(ScatteringTexture) scattering_texture,
                           IN(ScatteringTexture) single_mie_scattering_texture, IN(vec3) camera, IN(vec3) point,
                           IN(vec3) sun_direction, OUT(vec3) transmittance) {
  return GetSkyRadianceToPointWithShadow(atmosphere, transmittance_texture, scattering_texture,
                                         single_mie_scattering_texture, camera, point, 0.0, sun_direction,
                                         transmittance);
}
#endif

#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
// Direct sun irradiance on a surface at `point` with unit `normal`, and (out)
// the sky irradiance, from the table for a horizontal surface scaled by the
// fraction of the sky the tilted surface sees.
vec3 GetSunAndSkyIrradiance(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                            IN(IrradianceTexture) irradiance_texture, IN(vec3) point, IN(vec3) normal,
                            IN(vec3) sun_direction, OUT(vec3) sky_irradiance) {
  Number r = ClampRadius(atmosphere, length(point));
  Number mu_s = ClampCosine(dot(point, sun_direction) / length(point));
  sky_irradiance = GetIrradiance(atmosphere, irradiance_texture, r, mu_s) *
                   (1.0 + dot(normal, point) / length(point)) * 0.5;
  return atmosphere.solar_irradiance * GetTransmittanceToSun(atmosphere, transmittance_texture, r, mu_s) *
         max(dot(normal, sun_direction), 0.0);
}
#endif

// Radiance of the sun's disc at the top of the atmosphere.
vec3 GetSolarRadiance(IN(AtmosphereParameters) atmosphere) {
  return atmosphere.solar_irradiance / (PI * atmosphere.sun_angular_radius * atmosphere.sun_angular_radius);
}

// Linear sRGB (IEC 61966-2-1: Rec. 709 primaries, white D65) of CIE 1931 XYZ,
// for what a spectral set's functions return (SKYBAKE_CHANNELS_ARE_XYZ): the
// rows of the inverse of the primaries' XYZ matrix, which bake/colour.cpp
// derives from their chromaticities (Colour.RuntimeConvertsXyzToLinearSrgb
// holds the two equal). D65 white gives (1, 1, 1); a colour outside the
// gamut (a saturated twilight) gives a negative channel.
vec3 XyzToLinearSrgb(IN(vec3) xyz) {
  return vec3(dot(vec3(3.2409699, -1.5373832, -0.4986108), xyz),
              dot(vec3(-0.9692436, 1.8759675, 0.0415551), xyz),
              dot(vec3(0.0556301, -0.2039770, 1.0569715), xyz));
}
