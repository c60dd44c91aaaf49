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

// Trapezoidal intervals of the direct integration: an even number up to
// SEGMENT_INTERVALS, as many as SegmentIntervals finds the integrands need
// for a relative error of about SEGMENT_TOLERANCE. Near-horizontal segments
// need a few; the cap is reached by segments that climb through many
// aerosol scale heights (1.2 km on Earth), where 64 intervals leave 0.13 %
// on single Mie over 10 km straight up (16 left 2 %;
// AerialPerspective.DirectIntegrationMeetsItsToleranceWithFewIntervals).
const int SEGMENT_INTERVALS = 64;
const Number SEGMENT_TOLERANCE = 2e-4;

Number ProfileSampleAltitude(IN(AtmosphereParameters) atmosphere, int i) {
  Number x = Number(i) / Number(ALTITUDE_PROFILE_SIZE - 1);
  return (atmosphere.top_radius - atmosphere.bottom_radius) * x * x;
}

// Log-linear between two profile samples, per channel: exact for an
// exponential density, linear where a sample is 0 (a layer that ends).
vec3 InterpolateCoefficients(vec3 a, vec3 b, Number f) {
  vec3 tiny = vec3(1e-30);
  vec3 positive = step(tiny, min(a, b));
  return mix(mix(a, b, f), a * exp(f * log(max(b, tiny) / max(a, tiny))), positive);
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

// The mean of exp(-x) over [0, depth], (1 - exp(-depth)) / depth, from
// attenuation = exp(-depth); by its series where that would cancel.
vec3 MeanAttenuation(IN(vec3) depth, IN(vec3) attenuation) {
  return mix((vec3(1.0) - attenuation) / max(depth, vec3(1e-30)), vec3(1.0) - 0.5 * depth,
             vec3(1.0) - step(vec3(1e-4), depth));
}

// What the direct integration of a segment of the ray (r, mu) needs at one
// node, for the sun at (mu_s, nu): the extinction; the scattering of the
// groups the scattering table holds (divided by the Rayleigh phase
// function, as the table is) and of the Mie group (phase free), each times
// the sunlight reaching the node, attenuated as in the bake (transmittance
// table toward the sun, fraction of the disc above the horizon); and the
// total scattering coefficient.
struct SegmentNode {
  vec3 extinction;
  vec3 rayleigh;
  vec3 mie;
  vec3 scattering;
};

SegmentNode GetSegmentNode(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                           Number r, Number mu, Number mu_s, Number nu, Number t) {
  SegmentNode node;
  Number r_t = RadiusAtDistance(atmosphere, r, mu, t);
  Number mu_s_t = ClampCosine((r * mu_s + t * nu) / r_t);
  vec3 mie_scattering;
  vec3 rayleigh_scattering;
  node.extinction = GetCoefficientsAtAltitude(atmosphere, AltitudeAtDistance(atmosphere, r, mu, t, r_t),
                                              mie_scattering, rayleigh_scattering);
  vec3 sunlight = GetTransmittanceToSun(atmosphere, transmittance_texture, r_t, mu_s_t);
  node.rayleigh = rayleigh_scattering * sunlight;
  node.mie = mie_scattering * sunlight;
  node.scattering = rayleigh_scattering + mie_scattering;
  return node;
}

// The integrals along a segment from its start to the node `end`, by the
// trapezoidal rule: its optical depth and transmittance; the single
// scattering of the two groups (still without the solar irradiance); and
// the scattering weight, the integral of T(camera, t) * total scattering
// coefficient dt.
struct SegmentSums {
  vec3 optical_depth;
  vec3 transmittance;
  vec3 single_rayleigh;
  vec3 single_mie;
  vec3 scattering_weight;
  SegmentNode end;
};

// A segment of length 0 at distance t along the ray.
SegmentSums StartSegment(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                         Number r, Number mu, Number mu_s, Number nu, Number t) {
  SegmentSums sums;
  sums.optical_depth = vec3(0.0);
  sums.transmittance = vec3(1.0);
  sums.single_rayleigh = vec3(0.0);
  sums.single_mie = vec3(0.0);
  sums.scattering_weight = vec3(0.0);
  sums.end = GetSegmentNode(atmosphere, transmittance_texture, r, mu, mu_s, nu, t);
  return sums;
}

// The intervals a stretch of the ray of length L needs, from its
// integrands at its ends a, b and middle m: the extinction, and the
// scattering times the sunlight, each weighted by the transmittance from the
// stretch's start (its optical depth to m and b by the trapezoidal rule),
// as the sums weight them. Two estimates, the larger taken, rounded up to an
// even number (the middle is then a node) from 2 to SEGMENT_INTERVALS:
// - Richardson's: the trapezoidal rule on one interval and on two differ by
//   (a + b - 2 m) / 4 of L, and n intervals leave about 4/3 of that over
//   n^2, so n = sqrt(4 e / (3 SEGMENT_TOLERANCE)), e the largest
//   |a + b - 2 m| / (a + 2 m + b). It sees the curvature of the ray (whose
//   altitude grows as t^2 / 2r along the horizon) and of the sunlight's fall
//   toward a low sun, but e cannot exceed 1 however fast an integrand
//   changes;
// - the exponential's: an integrand that changes by a factor F along the
//   stretch, as exp(-k t), leaves (ln F / n)^2 / 12 relatively, so n =
//   ln F / sqrt(12 SEGMENT_TOLERANCE), F the largest ratio of two of the three.
// Near-horizontal stretches, whose altitude changes slowly, need the fewest.
vec3 SegmentCurvature(IN(vec3) a, IN(vec3) m, IN(vec3) b) {
  return abs(a + b - 2.0 * m) / max(a + b + 2.0 * m, vec3(1e-30));
}

vec3 SegmentRatio(IN(vec3) a, IN(vec3) m, IN(vec3) b) {
  return max(max(a, m), b) / max(min(min(a, m), b), vec3(1e-30));
}

Number LargestComponent(IN(vec3) v) { return max(max(v.x, v.y), v.z); }

int SegmentIntervals(IN(SegmentNode) a, IN(SegmentNode) m, IN(SegmentNode) b, Number L) {
  vec3 to_middle = exp(-(a.extinction + m.extinction) * (0.25 * L));
  vec3 to_end = to_middle * exp(-(m.extinction + b.extinction) * (0.25 * L));
  vec3 rayleigh_m = m.rayleigh * to_middle;
  vec3 rayleigh_b = b.rayleigh * to_end;
  vec3 mie_m = m.mie * to_middle;
  vec3 mie_b = b.mie * to_end;
  vec3 scattering_m = m.scattering * to_middle;
  vec3 scattering_b = b.scattering * to_end;
  Number e = LargestComponent(max(max(SegmentCurvature(a.extinction, m.extinction, b.extinction),
                                      SegmentCurvature(a.rayleigh, rayleigh_m, rayleigh_b)),
                                  max(SegmentCurvature(a.mie, mie_m, mie_b),
                                      SegmentCurvature(a.scattering, scattering_m, scattering_b))));
  Number F = LargestComponent(max(max(SegmentRatio(a.extinction, m.extinction, b.extinction),
                                      SegmentRatio(a.rayleigh, rayleigh_m, rayleigh_b)),
                                  max(SegmentRatio(a.mie, mie_m, mie_b),
                                      SegmentRatio(a.scattering, scattering_m, scattering_b))));
  Number n = max(sqrt(e / (0.75 * SEGMENT_TOLERANCE)), log(max(F, 1.0)) / sqrt(12.0 * SEGMENT_TOLERANCE));
  return 2 * int(clamp(ceil(0.5 * n), 1.0, Number(SEGMENT_INTERVALS / 2)));
}

// `sums` (of a segment that ends at distance t0 along the ray (r, mu))
// carried on to distance t1 >= t0. The sources are trapezoidal over each
// interval, the transmittance to the camera exponential within it: the
// interval's integral of T is T_start (1 - exp(-dtau)) / dtau, exact in a
// thick medium (where a trapezoid of T overshoots without bound) and T's
// trapezoid when thin. The nodes are found in one place, in the order the
// intervals need them: the last, the middle (which set the intervals), then
// the others from t0 on; a shader compiler then inlines one copy of
// GetSegmentNode, not three. A stretch of at most a hundredth of t1 (the
// rest of a segment that ends on the ground, found again by another route)
// is one interval: its trapezoid's error is of the order of that hundredth
// cubed.
SegmentSums ContinueSegment(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                            Number r, Number mu, Number mu_s, Number nu, Number t0, Number t1,
                            IN(SegmentSums) sums) {
  SegmentSums result = sums;
  if (t1 <= t0) return result;
  SegmentNode last = sums.end;
  SegmentNode middle = sums.end;
  SegmentNode previous = sums.end;
  bool short_stretch = t1 - t0 <= 0.01 * t1;
  int intervals = short_stretch ? 1 : 2;
  Number dt = (t1 - t0) / Number(intervals);
  // Step i < 0 finds the last node (and, unless the stretch is short, the
  // middle one); step i >= 0 adds interval k = i + 1, up to its end node.
  for (int i = short_stretch ? -1 : -2; i < intervals; ++i) {
    bool finding_last = i == -2 || (i == -1 && short_stretch);
    bool finding_middle = i == -1 && !short_stretch;
    int k = i + 1;
    SegmentNode node = last;
    if (finding_last || finding_middle || (k < intervals && 2 * k != intervals)) {
      Number t = finding_last ? t1 : (finding_middle ? 0.5 * (t0 + t1) : t0 + dt * Number(k));
      node = GetSegmentNode(atmosphere, transmittance_texture, r, mu, mu_s, nu, t);
    } else if (2 * k == intervals) {
      node = middle;
    }
    if (finding_last) {
      last = node;
    } else if (finding_middle) {
      middle = node;
      intervals = SegmentIntervals(sums.end, middle, last, t1 - t0);
      dt = (t1 - t0) / Number(intervals);
    } else {
      vec3 interval_depth = (previous.extinction + node.extinction) * (0.5 * dt);
      vec3 attenuation = exp(-interval_depth);
      vec3 mean_transmittance = result.transmittance * MeanAttenuation(interval_depth, attenuation);
      result.single_rayleigh += (previous.rayleigh + node.rayleigh) * (0.5 * dt) * mean_transmittance;
      result.single_mie += (previous.mie + node.mie) * (0.5 * dt) * mean_transmittance;
      result.scattering_weight += (previous.scattering + node.scattering) * (0.5 * dt) * mean_transmittance;
      result.optical_depth += interval_depth;
      result.transmittance *= attenuation;
      previous = node;
    }
  }
  result.end = last;
  return result;
}

// The optical depth of the segment of length d along (r, mu): the directly
// integrated one where its weight `direct` is 1, blended toward the tables'
// (GetOpticalDepth, read only where needed) as the weight falls.
vec3 BlendedOpticalDepth(IN(AtmosphereParameters) atmosphere, IN(TransmittanceTexture) transmittance_texture,
                         Number r, Number mu, Number d, bool ray_r_mu_intersects_ground,
                         IN(vec3) direct_optical_depth, Number direct) {
  if (direct >= 1.0) return direct_optical_depth;
  return mix(GetOpticalDepth(atmosphere, transmittance_texture, r, mu, d, ray_r_mu_intersects_ground),
             direct_optical_depth, direct);
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

  // The transmittance of the whole segment: integrated directly, blended
  // into the tables' (GetOpticalDepth) between one and two
  // DIRECT_SEGMENT_LENGTHs; the single Mie of its sunlit part the same way.
  // A colour's optical depths do not add (transmittance_is_colour): the
  // difference of the whole rays' optical depths of sunlight's colour from
  // the two ends is that of the wavelengths that survive the longer ray, too
  // small for the segment (it took 15 to 22 % off the aerial perspective
  // over 30 km near the horizon, docs/colour.md), so for colour the
  // transmittance of a segment of any length is integrated along it.
  bool colour = atmosphere.transmittance_is_colour != 0;
  Number lit_direct = 1.0 - smoothstep(DIRECT_SEGMENT_LENGTH, 2.0 * DIRECT_SEGMENT_LENGTH, lit);
  Number direct = colour ? 1.0 : 1.0 - smoothstep(DIRECT_SEGMENT_LENGTH, 2.0 * DIRECT_SEGMENT_LENGTH, d);
  Number lit_transmittance_direct = colour ? 1.0 : lit_direct;
  // The sunlit part integrated directly, unless it is longer than twice
  // DIRECT_SEGMENT_LENGTH and not a colour's (where the result reads the
  // tables alone).
  SegmentSums lit_sums;
  lit_sums.optical_depth = vec3(0.0);
  lit_sums.single_mie = vec3(0.0);
  if (lit_transmittance_direct > 0.0) {
    lit_sums = ContinueSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, 0.0, lit,
                               StartSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, 0.0));
  }
  vec3 optical_depth = lit_sums.optical_depth;
  if (direct > 0.0 && lit < d) {
    optical_depth =
        ContinueSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, lit, d, lit_sums).optical_depth;
  }
  transmittance = exp(-BlendedOpticalDepth(atmosphere, transmittance_texture, r, mu, d, ray_r_mu_intersects_ground,
                                            optical_depth, direct));

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
    SegmentSums far_sums = ContinueSegment(atmosphere, transmittance_texture, r, mu, mu_s, nu, lit, far, lit_sums);
    if (far < boundary) {
      Number r_far = RadiusAtDistance(atmosphere, r, mu, far);
      vec3 unused_far_mie;
      scattering -= far_sums.transmittance *
                    GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r_far,
                                          CosineAtDistance(r, mu, far, r_far), ClampCosine((r * mu_s + far * nu) / r_far),
                                          nu, ray_r_mu_intersects_ground, unused_far_mie);
    }
    vec3 multiple = max(scattering - far_sums.single_rayleigh * atmosphere.solar_irradiance, vec3(0.0)) *
                    lit_sums.scattering_weight / max(far_sums.scattering_weight, vec3(1e-30));
    return (lit_sums.single_rayleigh * atmosphere.solar_irradiance + multiple) * RayleighPhaseFunction(nu) +
           lit_sums.single_mie * atmosphere.solar_irradiance * MiePhaseFunction(atmosphere, nu);
  }
  // A longer sunlit part: the table method, with its transmittance and single
  // Mie blended from the direct integration up to twice DIRECT_SEGMENT_LENGTH.
  // The far end of the sunlit part:
  Number r_p = RadiusAtDistance(atmosphere, r, mu, lit);
  Number mu_p = CosineAtDistance(r, mu, lit, r_p);
  Number mu_s_p = ClampCosine((r * mu_s + lit * nu) / r_p);
  vec3 lit_transmittance = exp(-BlendedOpticalDepth(atmosphere, transmittance_texture, r, mu, lit,
                                                    ray_r_mu_intersects_ground, lit_sums.optical_depth,
                                                    lit_transmittance_direct));
  vec3 single_mie_scattering_p;
  vec3 scattering_p = GetCombinedScattering(atmosphere, scattering_texture, single_mie_scattering_texture, r_p,
                                            mu_p, mu_s_p, nu, ray_r_mu_intersects_ground,
                                            single_mie_scattering_p);
  scattering = max(scattering - lit_transmittance * scattering_p, vec3(0.0));
  single_mie_scattering = max(single_mie_scattering - lit_transmittance * single_mie_scattering_p, vec3(0.0));
  single_mie_scattering = mix(single_mie_scattering, lit_sums.single_mie * atmosphere.solar_irradiance, lit_direct);
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
