// skybake GLSL runtime: the scattering table's sun axis after sunset, where
// each ray has its own columns placed from its shadow edge (after
// table_mappings.glsl).

#if SKYBAKE_HAS_SCATTERING_TEXTURE
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
Number GetScatteringSplitMuS(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis) {
  return GetScatteringMuSFromUnitRangeOnAxis(
      atmosphere, sun_axis, Number(atmosphere.scattering_mu_s_split) / Number(atmosphere.scattering_mu_s_size - 1));
}

// X, a unit sun from 1 at the zenith to 0 at the tables' lowest sun (and
// on below it, negative and smooth), like GetScatteringUnitMuS but with
// Bruneton's k = 1, at sun zenith cosine mu_s, and its derivative in the
// sun zenith angle theta: with a = (d - d_min) / (d_max - d_min) (as there)
// and A its value at scattering_mu_s_min, X = (1 - a / A) / (1 + a); d =
// -R mu_s + sqrt(R^2 mu_s^2 + top^2 - R^2) (R the bottom radius) has dd/dmu_s
// = -R d / (d + R mu_s) and dmu_s/dtheta = -sin(theta). The axis's H and
// 1 / A come from sun_axis (GetScatteringSunAxis), found once per lookup.
Number ShadowEdgeUnitSun(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, Number mu_s,
                         OUT(Number) derivative) {
  Number bottom = atmosphere.bottom_radius;
  Number d = DistanceToTopAtmosphereBoundary(atmosphere, bottom, mu_s);
  Number d_min = atmosphere.top_radius - bottom;
  Number span = sun_axis.H - d_min;
  Number a = (d - d_min) / span;
  Number inverse_A = sun_axis.inverse_A;
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
Number ShadowEdgeLitUnitFrom(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, Number D,
                             IN(vec2) edge, Number X_closest, Number X_span, Number log_span,
                             OUT(Number) derivative) {
  Number dX_dtheta;
  Number X = ShadowEdgeUnitSun(atmosphere, sun_axis, ShadowEdgeSunCosine(edge, D), dX_dtheta);
  derivative = -SHADOW_EDGE_TABLES_WEIGHT * dX_dtheta * D / X_span + (1.0 - SHADOW_EDGE_TABLES_WEIGHT) / log_span;
  return SHADOW_EDGE_TABLES_WEIGHT * (X - X_closest) / X_span +
         (1.0 - SHADOW_EDGE_TABLES_WEIGHT) * log(D / SHADOW_EDGE_CLOSEST) / log_span;
}

// ShadowEdgeLitUnitFrom's constants for the edge, and the split's D.
void ShadowEdgeLitUnitSpans(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, IN(vec2) edge,
                            OUT(Number) X_closest, OUT(Number) X_span, OUT(Number) log_span,
                            OUT(Number) split_distance) {
  Number unused;
  Number split_mu_s = GetScatteringSplitMuS(atmosphere, sun_axis);
  X_closest = ShadowEdgeUnitSun(atmosphere, sun_axis, ShadowEdgeSunCosine(edge, SHADOW_EDGE_CLOSEST), unused);
  X_span = ShadowEdgeUnitSun(atmosphere, sun_axis, split_mu_s, unused) - X_closest;
  split_distance = ShadowEdgeDistance(edge, split_mu_s);
  log_span = log(split_distance / SHADOW_EDGE_CLOSEST);
}

Number ShadowEdgeLitUnit(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, Number distance,
                         IN(vec2) edge) {
  Number X_closest;
  Number X_span;
  Number log_span;
  Number split_distance;
  ShadowEdgeLitUnitSpans(atmosphere, sun_axis, edge, X_closest, X_span, log_span, split_distance);
  Number unused;
  return ShadowEdgeLitUnitFrom(atmosphere, sun_axis, clamp(distance, SHADOW_EDGE_CLOSEST, split_distance), edge,
                               X_closest, X_span, log_span, unused);
}

// Its inverse: D at position x in [0, 1], by Newton's method in s = ln D
// from the logarithm's term alone (x rises with s, at least at 1 - w times
// the logarithm's rate), to 1e-11 in ln D in a few steps.
Number ShadowEdgeLitDistance(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, Number x,
                             IN(vec2) edge) {
  Number X_closest;
  Number X_span;
  Number log_span;
  Number split_distance;
  ShadowEdgeLitUnitSpans(atmosphere, sun_axis, edge, X_closest, X_span, log_span, split_distance);
  Number s_min = log(SHADOW_EDGE_CLOSEST);
  Number s_max = s_min + log_span;
  Number s = mix(s_min, s_max, x);
  for (int i = 0; i < 12; ++i) {
    Number slope;
    Number error =
        ShadowEdgeLitUnitFrom(atmosphere, sun_axis, exp(s), edge, X_closest, X_span, log_span, slope) - x;
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
Number GetScatteringShadowEdgePosition(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis,
                                       Number D, IN(vec2) edge) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  if (D >= SHADOW_EDGE_CLOSEST) {
    return past +
           ShadowEdgeLitUnit(atmosphere, sun_axis, D, edge) * (Number(atmosphere.scattering_mu_s_split) - past);
  }
  if (D >= 0.0) return past - 1.0 + D / SHADOW_EDGE_CLOSEST;
  return past - 1.0 + D / ShadowEdgePastStep(atmosphere, edge);
}

// Its inverse: the sun's distance D to the edge at `position`.
Number GetScatteringShadowEdgeDistance(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis,
                                       Number position, IN(vec2) edge) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  if (position >= past) {
    Number x = (position - past) / (Number(atmosphere.scattering_mu_s_split) - past);
    return ShadowEdgeLitDistance(atmosphere, sun_axis, x, edge);
  }
  if (position >= past - 1.0) return (position - past + 1.0) * SHADOW_EDGE_CLOSEST;
  return (position - past + 1.0) * ShadowEdgePastStep(atmosphere, edge);
}
#endif
