// skybake GLSL runtime: the scattering table's 4D coordinates and the table
// lookups, with their blends along the sun axis (after shadow_edge.glsl).

#if SKYBAKE_HAS_SCATTERING_TEXTURE
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
vec4 GetScatteringTextureUvwzAndEdge(IN(AtmosphereParameters) atmosphere, IN(ScatteringSunAxis) sun_axis, Number r,
                                     Number mu, Number mu_s, Number nu, bool ray_r_mu_intersects_ground,
                                     OUT(vec2) edge) {
  Number rho = HorizonDistance(atmosphere, r);

  Number x_mu = GetUnitMuInHalf(atmosphere, r, rho, mu, ray_r_mu_intersects_ground);
  Number u_mu = GetTextureCoordFromUnitMuInHalf(x_mu, ray_r_mu_intersects_ground, atmosphere.scattering_mu_size);
  Number u_r = GetScatteringTextureUR(atmosphere, r, rho, ray_r_mu_intersects_ground, x_mu);

  // Below the split, the position on the ray's own columns.
  Number u_mu_s = GetScatteringTextureUMuSOnAxis(atmosphere, sun_axis, mu_s);
  Number mu_s_size = Number(atmosphere.scattering_mu_s_size);
  edge = vec2(0.0);
  if (atmosphere.scattering_mu_s_split > 0 && u_mu_s * mu_s_size - 0.5 < Number(atmosphere.scattering_mu_s_split)) {
    ShadowEdge(atmosphere, r, mu, ViewSunAzimuthCosine(mu, mu_s, nu), ray_r_mu_intersects_ground, edge);
    u_mu_s = (GetScatteringShadowEdgePosition(atmosphere, sun_axis, ShadowEdgeDistance(edge, mu_s), edge) + 0.5) /
             mu_s_size;
  }
  return vec4(ScatteringUnitNu(nu), u_mu_s, u_mu, u_r);
}

vec4 GetScatteringTextureUvwzFromRMuMuSNu(IN(AtmosphereParameters) atmosphere, Number r, Number mu,
                                          Number mu_s, Number nu, bool ray_r_mu_intersects_ground) {
  vec2 unused;
  return GetScatteringTextureUvwzAndEdge(atmosphere, GetScatteringSunAxis(atmosphere), r, mu, mu_s, nu,
                                         ray_r_mu_intersects_ground, unused);
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
//
// The geometric blends work on ln L: LogLight takes it of a texel's light,
// floored at DARK_LIGHT, and LightFromLog turns it back, 0 where it is dark
// (at most LOG_DARK_LIGHT, just above ln DARK_LIGHT = -69.08), so that a
// lookup takes one logarithm per texel it reads and one exponential.
const Number DARK_LIGHT = 1e-30;
const Number LOG_DARK_LIGHT = -69.0;

vec4 LogLight(vec4 light) { return log(max(light, vec4(DARK_LIGHT))); }

// 1 where ln L is above the dark floor, else 0.
vec4 IsLit(vec4 log_light) { return vec4(1.0) - step(log_light, vec4(LOG_DARK_LIGHT)); }

vec4 LightFromLog(vec4 log_light) { return exp(log_light) * IsLit(log_light); }

vec4 SunCosineMix(vec4 a, vec4 b, Number t, bool low_sun) {
  if (!low_sun) return mix(a, b, t);
  return LightFromLog(mix(LogLight(a), LogLight(b), t));
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
  // The first test is constant for a bake's tables: in a scene whose suns
  // stay high (scattering_mu_s_min above LOW_SUN_MU_S, where x_low_sun lies
  // below every column) it lets the compiler leave out the low-sun blends,
  // as a scattering_mu_s_split of 0 leaves out the rays' own columns.
  low_sun_below = atmosphere.scattering_mu_s_min < LOW_SUN_MU_S && x_below < x_low_sun;
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
// geometric blend (SunCosineMix). LogMonotoneCubic takes and returns ln L
// (LogLight), LogMonotoneCubicMix the light.
vec4 LogMonotoneCubic(vec4 log_a, vec4 lb, vec4 lc, vec4 log_d, bool has_a, bool has_d, Number t) {
  vec4 la = has_a ? log_a : 2.0 * lb - lc;
  vec4 ld = has_d ? log_d : 2.0 * lc - lb;
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
  return mix(mix(lb, lc, t), cubic, IsLit(min(min(log_a, lb), min(lc, log_d))));
}

vec4 LogMonotoneCubicMix(vec4 a, vec4 b, vec4 c, vec4 d, bool has_a, bool has_d, Number t) {
  return LightFromLog(LogMonotoneCubic(LogLight(a), LogLight(b), LogLight(c), LogLight(d), has_a, has_d, t));
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
// grid's lowest sun the same way. From ln a and ln b (LogLight).
void LowestSunLogFall(IN(vec4) log_a, IN(vec4) log_b, Number mu_s_a, Number mu_s_b, OUT(vec4) slope,
                      OUT(vec4) curvature) {
  vec4 rise = (log_b - log_a) * IsLit(log_a) * (vec4(1.0) - step(log_b, log_a));
  if (mu_s_b < 0.0) {
    vec4 k = rise / (mu_s_a * mu_s_a - mu_s_b * mu_s_b);
    slope = -2.0 * mu_s_a * k;
    curvature = -k;
  } else {
    slope = rise / (mu_s_b - mu_s_a);
    curvature = vec4(0.0);
  }
}

// The light at a column at sun cosine mu_s_a, ln a, continued to mu_s below
// it as LowestSunLogFall of ln a and ln b (at mu_s_b) has ln L fall.
vec4 LowestSunContinued(IN(vec4) log_a, IN(vec4) log_b, Number mu_s_a, Number mu_s_b, Number mu_s) {
  vec4 slope;
  vec4 curvature;
  LowestSunLogFall(log_a, log_b, mu_s_a, mu_s_b, slope, curvature);
  Number d = mu_s - mu_s_a;
  return LightFromLog(log_a + d * (slope + d * curvature));
}

// The light of nu slice nu_slice at the mu_s texel column at texture
// coordinate x, bilinear in (mu, r) by the texture unit.
vec4 GetScatteringInSlice(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                          IN(vec4) uvwz, Number x, Number nu_slice) {
  return SampleTexture3D(scattering_texture,
                         vec3((nu_slice + x) / Number(atmosphere.scattering_nu_size), uvwz.z, uvwz.w));
}

// ln L at the mu_s texel column at texture coordinate x (LogLight): the two
// nu slices either side of nu blended as SunCosineMix blends them.
vec4 GetLogScatteringAtMuSColumn(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                                 IN(vec4) uvwz, Number x, Number nu_slice, Number nu_t, bool low_sun) {
  vec4 a = GetScatteringInSlice(atmosphere, scattering_texture, uvwz, x, nu_slice);
  vec4 b = GetScatteringInSlice(atmosphere, scattering_texture, uvwz, x, nu_slice + 1.0);
  return low_sun ? mix(LogLight(a), LogLight(b), nu_t) : LogLight(mix(a, b, nu_t));
}

// The light of one nu slice at a ray's own column (below the split).
vec4 GetScatteringAtOwnColumn(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                              IN(vec4) uvwz, Number column, Number nu_slice) {
  return GetScatteringInSlice(atmosphere, scattering_texture, uvwz,
                              (column + 0.5) / Number(atmosphere.scattering_mu_s_size), nu_slice);
}

// ln L (LogLight) of one nu slice below the split at `position` on the ray's
// own columns (GetScatteringShadowEdgePosition): between its lit columns
// LogMonotoneCubic of the four around it (the split's column the last);
// within SHADOW_EDGE_CLOSEST of the edge, the light at the edge plus the
// rise to the first lit column times (D / D_min)^p, p from the rise to the
// second (where both rise, in [1, 10]; else 3, the fall of the light next
// to the edge), log_first_span = ln(D_1 / D_min) with D_1 the second lit
// column's distance to the edge; past the edge SunCosineMix of the two
// columns around it.
vec4 GetLogScatteringBelowSplit(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                                IN(vec4) uvwz, Number position, Number nu_slice, Number log_first_span) {
  Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
  Number intervals = Number(atmosphere.scattering_mu_s_split) - past;
  if (position >= past) {
    Number k = min(floor(position - past), intervals - 1.0);
    Number column = past + k;
    Number last = min(column + 2.0, past + intervals);
    vec4 la = LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column - 1.0, nu_slice));
    vec4 lb = LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column, nu_slice));
    vec4 lc = LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, column + 1.0, nu_slice));
    vec4 ld = LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, last, nu_slice));
    return LogMonotoneCubic(la, lb, lc, ld, k >= 1.0, k + 2.0 <= intervals, position - column);
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
    return LogLight(at_edge + rise * pow(vec4(position - past + 1.0), power));
  }
  Number x = past - 1.0 - position;
  Number k = min(floor(x), past - 2.0);
  return mix(LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past - 1.0 - k, nu_slice)),
             LogLight(GetScatteringAtOwnColumn(atmosphere, scattering_texture, uvwz, past - 2.0 - k, nu_slice)), x - k);
}

// Where a lookup of the scattering tables reads and how it blends, for one
// ray and sun: found once (GetScatteringLookup) and applied to each table
// (GetScatteringFromLookup), so that the single Mie table costs fetches and
// blends but none of the coordinates' arithmetic.
const int SCATTERING_DAYLIGHT = 0;          // linear along mu_s: one fetch per nu slice at x.x
const int SCATTERING_LOW_SUN = 1;           // LogMonotoneCubic of the columns at x, at t
const int SCATTERING_BELOW_TABLE = 2;       // LowestSunContinued of the columns at x.x and x.y
const int SCATTERING_OWN_COLUMNS = 3;       // GetLogScatteringBelowSplit in each nu slice, at position
struct ScatteringLookup {
  int kind;
  vec4 uvwz;         // GetScatteringTextureUvwzAndEdge
  Number nu_slice;   // the lower of the two nu slices, and the position between them
  Number nu_t;
  vec4 x;            // the mu_s columns' coordinates within a slice
  bvec4 low_sun;     // per column: its two nu slices blended geometrically
  bool has_first;    // SCATTERING_LOW_SUN: whether x.x and x.w are columns of their own
  bool has_last;
  Number t;          // SCATTERING_LOW_SUN: between x.y and x.z
  Number mu_s_a;     // SCATTERING_BELOW_TABLE: the sun cosines of x.x and x.y, and the sun's
  Number mu_s_b;
  Number mu_s;
  Number position;        // SCATTERING_OWN_COLUMNS
  Number log_first_span;
};

ScatteringLookup GetScatteringLookup(IN(AtmosphereParameters) atmosphere, Number r, Number mu, Number mu_s,
                                     Number nu, bool ray_r_mu_intersects_ground) {
  ScatteringLookup lookup;
  vec2 edge;
  ScatteringSunAxis sun_axis = GetScatteringSunAxis(atmosphere);
  lookup.uvwz =
      GetScatteringTextureUvwzAndEdge(atmosphere, sun_axis, r, mu, mu_s, nu, ray_r_mu_intersects_ground, edge);
  Number nu_size = Number(atmosphere.scattering_nu_size);
  Number nu_coord = lookup.uvwz.x * (nu_size - 1.0);
  lookup.nu_slice = min(floor(nu_coord), nu_size - 2.0);
  lookup.nu_t = nu_coord - lookup.nu_slice;
  lookup.low_sun = bvec4(true);
  lookup.has_first = false;
  lookup.has_last = false;
  lookup.t = 0.0;
  lookup.mu_s_a = 0.0;
  lookup.mu_s_b = 0.0;
  lookup.mu_s = mu_s;
  lookup.log_first_span = 1.0;
  Number mu_s_size = Number(atmosphere.scattering_mu_s_size);
  lookup.position = lookup.uvwz.y * mu_s_size - 0.5;
  if (atmosphere.scattering_mu_s_split > 0 && lookup.position < Number(atmosphere.scattering_mu_s_split)) {
    Number past = Number(SHADOW_EDGE_PAST_COLUMNS);
    lookup.kind = SCATTERING_OWN_COLUMNS;
    lookup.x = vec4(0.0);
    if (lookup.position < 0.0) {
      // Past the first column (the tables' lowest sun, or
      // SHADOW_EDGE_LEAST_PAST_SPAN past the edge): ln L continued from
      // the first two (LowestSunLogFall), as below the tables' lowest sun.
      Number step = ShadowEdgePastStep(atmosphere, edge);
      lookup.kind = SCATTERING_BELOW_TABLE;
      lookup.x = vec4(0.5, 1.5, 0.0, 0.0) / mu_s_size;
      lookup.mu_s_a = ShadowEdgeSunCosine(edge, -(past - 1.0) * step);
      lookup.mu_s_b = ShadowEdgeSunCosine(edge, -(past - 2.0) * step);
    } else if (lookup.position >= past - 1.0 && lookup.position < past) {
      Number x = 1.0 / (Number(atmosphere.scattering_mu_s_split) - past);
      lookup.log_first_span = log(ShadowEdgeLitDistance(atmosphere, sun_axis, x, edge) / SHADOW_EDGE_CLOSEST);
    }
    return lookup;
  }
  Number x_below;
  Number x_above;
  bool low_sun_below;
  Number x_low_sun = GetScatteringTextureUMuSOnAxis(atmosphere, sun_axis, LOW_SUN_MU_S);
  GetScatteringMuSColumns(atmosphere, lookup.uvwz.y, x_low_sun, x_below, x_above, lookup.t, low_sun_below);
  if (!low_sun_below) {
    // Daylight: linear along mu_s, which the texture unit does within a nu
    // slice, so one fetch at t between the two columns reads their blend.
    lookup.kind = SCATTERING_DAYLIGHT;
    lookup.x = vec4(mix(x_below, x_above, lookup.t), 0.0, 0.0, 0.0);
    lookup.low_sun = bvec4(false);
    return lookup;
  }
  if (lookup.t < 0.0) {
    lookup.kind = SCATTERING_BELOW_TABLE;
    lookup.x = vec4(x_below, x_above, 0.0, 0.0);
    lookup.low_sun = bvec4(true, x_above < x_low_sun, true, true);
    lookup.mu_s_a = atmosphere.scattering_mu_s_min;
    lookup.mu_s_b = GetScatteringMuSFromUnitRangeOnAxis(atmosphere, sun_axis, 1.0 / (mu_s_size - 1.0));
    return lookup;
  }
  Number column = x_below * mu_s_size - 0.5;
  Number x_last = (min(column + 2.0, mu_s_size - 1.0) + 0.5) / mu_s_size;
  lookup.kind = SCATTERING_LOW_SUN;
  lookup.x = vec4((max(column - 1.0, 0.0) + 0.5) / mu_s_size, x_below, x_above, x_last);
  lookup.low_sun = bvec4(true, true, x_above < x_low_sun, x_last < x_low_sun);
  lookup.has_first = column > 0.5;
  lookup.has_last = column + 2.0 < mu_s_size - 0.5;
  return lookup;
}

// The lookup applied to one table: in daylight two fetches (the texture unit
// blends the two mu_s columns); for a low sun between two columns
// LogMonotoneCubic of the four around it (eight fetches); below the table's
// lowest sun, or past a ray's first own column, LowestSunLogFall of the two
// lowest (four fetches); below the split, each nu slice's ln L on the ray's
// own columns (GetLogScatteringBelowSplit, up to four fetches each), linear
// between the two slices. Away from daylight, one logarithm per texel read
// and one exponential.
vec4 GetScatteringFromLookup(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                             IN(ScatteringLookup) lookup) {
  if (lookup.kind == SCATTERING_DAYLIGHT) {
    return mix(GetScatteringInSlice(atmosphere, scattering_texture, lookup.uvwz, lookup.x.x, lookup.nu_slice),
               GetScatteringInSlice(atmosphere, scattering_texture, lookup.uvwz, lookup.x.x, lookup.nu_slice + 1.0),
               lookup.nu_t);
  }
  if (lookup.kind == SCATTERING_OWN_COLUMNS) {
    return LightFromLog(mix(GetLogScatteringBelowSplit(atmosphere, scattering_texture, lookup.uvwz, lookup.position,
                                                       lookup.nu_slice, lookup.log_first_span),
                            GetLogScatteringBelowSplit(atmosphere, scattering_texture, lookup.uvwz, lookup.position,
                                                       lookup.nu_slice + 1.0, lookup.log_first_span),
                            lookup.nu_t));
  }
  vec4 a = GetLogScatteringAtMuSColumn(atmosphere, scattering_texture, lookup.uvwz, lookup.x.x, lookup.nu_slice,
                                       lookup.nu_t, lookup.low_sun.x);
  vec4 b = GetLogScatteringAtMuSColumn(atmosphere, scattering_texture, lookup.uvwz, lookup.x.y, lookup.nu_slice,
                                       lookup.nu_t, lookup.low_sun.y);
  if (lookup.kind == SCATTERING_BELOW_TABLE) {
    return LowestSunContinued(a, b, lookup.mu_s_a, lookup.mu_s_b, lookup.mu_s);
  }
  vec4 c = GetLogScatteringAtMuSColumn(atmosphere, scattering_texture, lookup.uvwz, lookup.x.z, lookup.nu_slice,
                                       lookup.nu_t, lookup.low_sun.z);
  vec4 d = GetLogScatteringAtMuSColumn(atmosphere, scattering_texture, lookup.uvwz, lookup.x.w, lookup.nu_slice,
                                       lookup.nu_t, lookup.low_sun.w);
  return LightFromLog(LogMonotoneCubic(a, b, c, d, lookup.has_first, lookup.has_last, lookup.t));
}

// The 4D lookup of one table.
vec4 GetScattering(IN(AtmosphereParameters) atmosphere, IN(ScatteringTexture) scattering_texture,
                   Number r, Number mu, Number mu_s, Number nu, bool ray_r_mu_intersects_ground) {
  return GetScatteringFromLookup(atmosphere, scattering_texture,
                                 GetScatteringLookup(atmosphere, r, mu, mu_s, nu, ray_r_mu_intersects_ground));
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

