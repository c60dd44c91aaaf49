// The CPU bake. The structure follows Bruneton's precomputation (transmittance,
// single scattering, then per order: scattering density, indirect irradiance,
// multiple scattering), with four CPU-specific choices:
//
// * Rays are shared. Every texel of the 4D table with the same (r, mu) looks
//   along the same ray, so the samples along it, the densities and the
//   optical depth from the camera are computed once per ray and reused by all
//   (mu_s, nu) texels; only the sun's transmittance and the looked-up source
//   differ.
// * Incoming radiance is shared. The radiance arriving at a point depends on
//   its altitude and the sun's zenith angle, not on the view direction, so
//   the scattering density gathers the incoming radiance once per (r, mu_s)
//   slice and reuses it for all (mu, nu) view texels of the slice.
// * Gathering is a weighted sum. Along a ray the scattering density J is
//   taken as linear between samples and the rest of the integrand as
//   exponential, so the weights are computed once per ray and each of its
//   texels sums weight times J. Being linear in J, it can also gather the
//   summed densities of all orders once, when each order's own radiance is
//   gathered on a coarser grid (BakeSettings::higher_order_divisor).
// * The innermost loops run over a ray's sun directions, in float, and
//   vectorise (bake/float_math.h); the geometry that decides the planet's
//   shadow stays in double.
//   docs/benchmark.md measures each choice's time and error.
//
// Integrals along rays use the exponential trapezoid rule (exact when the
// integrand varies exponentially between samples, as densities and
// transmittances do), so a thin haze layer seen on a steep ray needs no more
// samples than the thick Rayleigh layer.
#include "bake/bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "bake/float_math.h"
#include "bake/medium.h"
#include "core/constants.h"
#include "core/errors.h"
#include "shaders_runtime/runtime.h"

namespace skybake {

namespace {

using glsl::AtmosphereParameters;
using glsl::Texture;
using glsl::vec3;
using glsl::vec4;
// Intervals of a ray that are partly shadowed (the planet's shadow edge
// crosses them, or the sun's disc is partly hidden) are integrated on this
// many sub-intervals. Against 16 (evaluated in double), the Earth's single
// scattering moved by at most 0.38% (with 4: 1.1%; values below 1e-4
// weighted down); against brute force, see
// SingleScattering.MatchesBruteForceQuadratureWithinHalfPercent.
constexpr int kShadowEdgeSubdivisions = 8;

// Integral over an interval of width h of a positive function that takes the
// values a and b at its ends, assuming it is exponential in between; the
// ordinary trapezoid where that assumption cannot hold (a zero end).
double ExponentialTrapezoid(double a, double b, double h) {
  if (a <= 0.0 || b <= 0.0) return 0.5 * h * (a + b);
  double ratio = b / a;
  if (std::abs(ratio - 1.0) < 1e-4) return 0.5 * h * (a + b);
  return h * (b - a) / std::log(ratio);
}

// Weights (w_a, w_b) of the integral over an interval of width h of
// s(t) g(t), where the source s is linear between its end values s_a, s_b
// and the factor g exponential between g_a and g_b, with lambda = ln(g_b /
// g_a): the integral is w_a s_a + w_b s_b. lambda comes from the caller's
// logarithms, so an end that underflowed to 0 (beyond an optical depth of
// ~745) still decays at its true rate; where an end is truly 0 (lambda is
// not finite), g is taken as linear instead. Written so that neither a
// small nor a large lambda loses digits.
std::pair<double, double> LinearTimesExponentialWeights(double g_a, double g_b, double lambda, double h) {
  if (!std::isfinite(lambda)) return {h * (g_a / 3.0 + g_b / 6.0), h * (g_a / 6.0 + g_b / 3.0)};
  if (std::abs(lambda) < 0.1) {
    // w_a = h g_a sum lambda^n / (n+2)!, w_b = h g_a sum (n+1) lambda^n / (n+2)!
    double w_a = 0.0, w_b = 0.0, term = 0.5;
    for (int n = 0; n < 6; ++n) {
      w_a += term;
      w_b += (n + 1) * term;
      term *= lambda / (n + 3);
    }
    return {h * g_a * w_a, h * g_a * w_b};
  }
  const double lambda2 = lambda * lambda;
  return {h * (g_b - g_a * (1.0 + lambda)) / lambda2, h * (g_a - g_b * (1.0 - lambda)) / lambda2};
}

// A sample of an inscattering integrand along a view ray,
//   value = source * exp(-(view_optical_depth + sun_optical_depth)),
// with its factors and the extinction coefficient there (the rate at which
// view_optical_depth grows with distance) for optically thick intervals.
struct RayIntegrand {
  Spectrum source{0.0};
  Spectrum view_optical_depth{0.0};
  Spectrum sun_optical_depth{0.0};
  Spectrum extinction{0.0};
  Spectrum value{0.0};
};

// Integral over an interval of a ray from the view's optical depth tau_a to
// tau_b of the light scattered there per unit optical depth, value_a and
// value_b at the ends, attenuated by the view's optical depth and by the
// sun's, sun_a and sun_b at the ends (IntegrateInterval's rule for
// optically thick intervals, for one channel): exponential per unit optical
// depth between the ends, linear where an end is dark.
double IntegrateOverOpticalDepth(double value_a, double value_b, double sun_a, double sun_b, double tau_a,
                                 double tau_b) {
  const double width = tau_b - tau_a;
  if (value_a <= 0.0 || value_b <= 0.0) {
    // With u the view's optical depth from a and g the values without the
    // view's attenuation: integral over [0, width] of (ga + (gb - ga) u / width) exp(-u).
    const double ga = value_a * std::exp(-sun_a), gb = value_b * std::exp(-sun_b);
    const double decay = -std::expm1(-width), ramp = (decay - width * std::exp(-width)) / width;
    return std::exp(-tau_a) * (ga * decay + (gb - ga) * ramp);
  }
  const double log_a = std::log(value_a) - (tau_a + sun_a), log_b = std::log(value_b) - (tau_b + sun_b);
  const double fa = std::exp(log_a), fb = std::exp(log_b), log_ratio = log_b - log_a;
  return std::abs(log_ratio) < 1e-4 ? 0.5 * width * (fa + fb) : width * (fb - fa) / log_ratio;
}

// Integral between two samples of a RayIntegrand, `h` apart. Three failures
// of ExponentialTrapezoid on the product in optically thick media are
// avoided (docs/stability.md, "Integrals along rays"):
// * Over an interval of optical depth dtau >> 1 where the density also
//   changes, the product decays fastest where the medium is densest, not at
//   one mean rate; the trapezoid then returned up to ~1.5 times the exact
//   integral of beta_s exp(-tau), so orders could grow instead of shrink and
//   a dense fog's orders diverged. Here the integral is taken over the
//   view's optical depth, integrand * dt = (integrand / extinction) * dtau,
//   wherever an interval is more than one optical depth thick,
//   the integrand per unit optical depth varying exponentially (linearly if
//   an end is 0) between the samples: a mean of the two ends times at most
//   exp(-tau_a) - exp(-tau_b), which can never exceed the light that enters.
// * An end where the density is 0 (a vacuum gap, or an exponential profile
//   that underflowed far above its scale height) made the trapezoid take
//   half the interval times the other end: with a kilometre-thin layer on
//   a megametre-long interval, single scattering above the sun's
//   irradiance. Such an end takes the other end's value per unit optical
//   depth, as the light scattered per unit optical depth does not vanish
//   with the density.
// * Beyond an optical depth of ~745, exp(-tau) underflows to 0 and an end
//   looked like a zero of the integrand; rates from logarithms do not.
// Over optically thin intervals (the common case) the exponential trapezoid
// in distance is kept: it cannot overshoot there (an end that underflows
// through the sun's optical depth gives at most half the interval's optical
// depth times the other end), it is the more accurate assumption (the sun's
// attenuation varies exponentially with distance, not with the view's
// optical depth: measured against brute force in
// SingleScattering.MatchesBruteForceQuadratureWithinHalfPercent), and the
// cheaper one.
Spectrum IntegrateInterval(const RayIntegrand& a, const RayIntegrand& b, double h) {
  Spectrum result;
  for (int c = 0; c < 3; ++c) {
    const double view_depth = b.view_optical_depth[c] - a.view_optical_depth[c];
    const double extinction_a = a.extinction[c], extinction_b = b.extinction[c];
    if (!(view_depth > 1.0 && (extinction_a > 0.0 || extinction_b > 0.0))) {
      result[c] = ExponentialTrapezoid(a.value[c], b.value[c], h);
      continue;
    }
    // Per unit of the view's optical depth; an end that is truly dark (in
    // the planet's shadow, or nothing scatters) makes the rule linear.
    const double value_a = extinction_a > 0.0 ? a.source[c] / extinction_a : b.source[c] / extinction_b;
    const double value_b = extinction_b > 0.0 ? b.source[c] / extinction_b : value_a;
    result[c] = IntegrateOverOpticalDepth(value_a, value_b, a.sun_optical_depth[c], b.sun_optical_depth[c],
                                          a.view_optical_depth[c], b.view_optical_depth[c]);
  }
  return result;
}

// Sample distances along a ray of length d: n equal intervals. (Grading them
// toward the ray's lowest point was measured against brute force: it helped
// no daylight case and hurt twilight rays, lit only far from the camera.)
std::vector<double> RayDistances(double d, int n) {
  std::vector<double> t(n + 1);
  for (int k = 0; k <= n; ++k) t[k] = d * k / n;
  return t;
}

// The n-point Gauss-Legendre rule mapped to [a, b] (Newton's method on the
// Legendre recurrence), appended to nodes and weights.
void AppendGaussLegendre(int n, double a, double b, std::vector<double>& nodes, std::vector<double>& weights) {
  for (int i = 0; i < n; ++i) {
    double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
    double derivative = 1.0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1, p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1.0);
      double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-15) break;
    }
    nodes.push_back(0.5 * (a + b) + 0.5 * (b - a) * x);
    weights.push_back((b - a) / ((1.0 - x * x) * derivative * derivative));
  }
}

// Samples along one ray of the scattering table, shared by its (mu_s, nu) texels.
struct RaySamples {
  double r = 0.0, mu = 0.0;
  bool intersects_ground = false;
  std::vector<double> t, radius;  // t[0] = 0 ... t[n] = end of the ray
  std::vector<Spectrum> optical_depth;           // from the camera to each sample
  std::vector<Spectrum> extinction;              // extinction coefficient at each sample
  std::vector<std::vector<Spectrum>> scattering;  // [group][sample] scattering coefficient

  // Whether the view's optical depth over interval k (from sample k to
  // k + 1) is at most 1 in every channel.
  bool ThinInterval(int k) const {
    const Spectrum depth = optical_depth[k + 1] - optical_depth[k];
    return std::max({depth.x, depth.y, depth.z}) <= 1.0;
  }
};

// Sums over the scattering table, per channel, of the accumulated table and
// of the newest order, both divided by the Rayleigh phase as the table is.
struct OrderSums {
  Spectrum table{0.0}, newest{0.0};
};

// Order-by-order convergence of the scattering orders. Past the first few
// orders each order is close to the previous one times a constant ratio q
// (the dominant eigenvalue of the scattering operator), so the orders not
// computed sum to newest * q / (1 - q). Ratios and sizes are per channel and
// global over the table: per texel ratios are noisy where orders are tiny.
class OrderConvergence {
 public:
  void Add(const OrderSums& sums) {
    previous_ratio_ = ratio_;
    ratio_ = has_newest_ ? Divide(sums.newest, newest_) : Spectrum(-1.0);
    has_previous_ratio_ = has_ratio_;
    has_ratio_ = has_newest_;
    newest_ = sums.newest;
    has_newest_ = true;
    relative_ = Divide(sums.newest, sums.table);
  }
  bool NewestIsZero() const { return Max(newest_) <= 0.0; }
  // Largest ratio over the channels (0 before the third order).
  double Ratio() const { return has_ratio_ ? std::max(0.0, Max(ratio_)) : 0.0; }
  // Estimate of the orders not computed, relative to the table: the
  // geometric tail if the ratio is known and below 1, otherwise the newest
  // order alone (a lower bound).
  double RemainingWithoutTail() const {
    double remaining = 0.0;
    for (int c = 0; c < 3; ++c) {
      bool geometric = has_ratio_ && ratio_[c] >= 0.0 && ratio_[c] < kMaxRatio;
      remaining = std::max(remaining, geometric ? relative_[c] * ratio_[c] / (1.0 - ratio_[c]) : relative_[c]);
    }
    return remaining;
  }
  // q / (1 - q) per channel once the ratio is known twice and below
  // kMaxRatio (a ratio near or above 1 means the series is not yet geometric).
  std::optional<Spectrum> TailFactor() const {
    if (!has_previous_ratio_) return std::nullopt;
    Spectrum factor(0.0);
    for (int c = 0; c < 3; ++c) {
      if (relative_[c] <= 0.0) continue;
      if (ratio_[c] < 0.0 || ratio_[c] >= kMaxRatio || previous_ratio_[c] < 0.0) return std::nullopt;
      factor[c] = ratio_[c] / (1.0 - ratio_[c]);
    }
    return factor;
  }
  double RelativeTail() const {
    std::optional<Spectrum> factor = TailFactor();
    return factor ? Max(relative_ * *factor) : 0.0;
  }
  // Error of the extrapolated tail: its derivative newest / (1 - q)^2 with
  // respect to q times the change of q over the last order.
  double TailError() const {
    if (!TailFactor()) return std::numeric_limits<double>::infinity();
    double error = 0.0;
    for (int c = 0; c < 3; ++c) {
      if (relative_[c] <= 0.0) continue;
      double one_minus_q = 1.0 - ratio_[c];
      error = std::max(error, relative_[c] * std::abs(ratio_[c] - previous_ratio_[c]) / (one_minus_q * one_minus_q));
    }
    return error;
  }

 private:
  static constexpr double kMaxRatio = 0.999;
  // a / b per channel; 0 where b is 0 (nothing to compare against).
  static Spectrum Divide(const Spectrum& a, const Spectrum& b) {
    Spectrum q(0.0);
    for (int c = 0; c < 3; ++c) q[c] = b[c] > 0.0 ? a[c] / b[c] : 0.0;
    return q;
  }
  static double Max(const Spectrum& v) { return std::max({v.x, v.y, v.z}); }

  bool has_newest_ = false, has_ratio_ = false, has_previous_ratio_ = false;
  Spectrum newest_{0.0}, relative_{0.0}, ratio_{0.0}, previous_ratio_{0.0};
};

// The grid of each higher order's radiance: the r and mu sizes of the grid
// of the scattering densities divided by `divisor` (mu kept even). mu_s and nu are kept: halving
// mu_s as well raised the sky irradiance error of the report's case set
// from 12.6% to 15.4% RMS and tripled its twilight error, as the light of
// low suns changes fastest with mu_s.
AtmosphereParameters HigherOrderGrid(AtmosphereParameters grid, int divisor) {
  grid.scattering_r_size = std::max(2, grid.scattering_r_size / divisor);
  grid.scattering_mu_size = std::max(4, grid.scattering_mu_size / divisor / 2 * 2);
  return grid;
}

// target += source * factor, per channel, over the rgb of every texel.
// f(row, first, end) over the rows of a texture (y and z) in parallel:
// first and end are the row's texel offsets into texels.
template <typename F>
void ForEachRow(const Texture& texture, F&& f) {
  const std::size_t row_size = std::size_t(4) * texture.width;
  tbb::parallel_for(0, texture.height * texture.depth, [&](int row) {
    f(row, row * row_size, (row + 1) * row_size);
  });
}

void AddScaled(const Texture& source, const Spectrum& factor, Texture& target) {
  ForEachRow(target, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      for (int c = 0; c < 3; ++c) target.texels[i + c] += float(source.texels[i + c] * factor[c]);
    }
  });
}

Texture ScatteringGridTexture(const AtmosphereParameters& grid) {
  return Texture(grid.scattering_nu_size * grid.scattering_mu_s_size, grid.scattering_mu_size, grid.scattering_r_size);
}

// Per texel column x of a scattering grid, the sun's cosine mu_s and the
// nu of the column's slice: they depend on x alone.
struct SunColumns {
  std::vector<double> mu_s, grid_nu;
  int mu_s_size = 0, nu_size = 0;
  explicit SunColumns(const AtmosphereParameters& grid)
      : mu_s_size(grid.scattering_mu_s_size), nu_size(grid.scattering_nu_size) {
    for (int x = 0; x < mu_s_size * nu_size; ++x) {
      const ScatteringTexel texel = GetScatteringTexel(grid, x, 0, 0);
      mu_s.push_back(texel.mu_s), grid_nu.push_back(texel.grid_nu);
    }
  }
};

// The distinct sun directions of one ray (view cosine mu) of a scattering
// grid: its (mu_s, nu) texels, nu clamped as GetScatteringTexel clamps it to
// the range that mu and mu_s allow, with the slices that clamping gave the
// same nu merged, as their integrals are the same.
struct SunDirections {
  std::vector<double> mu_s, nu;  // per direction
  std::vector<int> of_texel;     // texel x -> direction
};

SunDirections RaySunDirections(const SunColumns& columns, double mu) {
  SunDirections directions;
  directions.of_texel.resize(columns.mu_s.size());
  for (int mu_s_index = 0; mu_s_index < columns.mu_s_size; ++mu_s_index) {
    for (int nu_index = 0; nu_index < columns.nu_size; ++nu_index) {
      const int x = nu_index * columns.mu_s_size + mu_s_index;
      const double mu_s = columns.mu_s[x];
      const double nu = ClampedNu(columns.grid_nu[x], mu, mu_s);
      if (nu_index == 0 || nu != directions.nu.back()) {
        directions.mu_s.push_back(mu_s);
        directions.nu.push_back(nu);
      }
      directions.of_texel[x] = static_cast<int>(directions.nu.size()) - 1;
    }
  }
  return directions;
}

// The rgb of a 2D texture as one plane per channel (gathers of one channel).
struct ChannelPlanes {
  int width = 0, height = 0;
  std::vector<float> channel[3];
  explicit ChannelPlanes(const Texture& texture) : width(texture.width), height(texture.height) {
    for (int c = 0; c < 3; ++c) {
      channel[c].resize(std::size_t(width) * height);
      for (std::size_t i = 0; i < channel[c].size(); ++i) channel[c][i] = texture.texels[4 * i + c];
    }
  }
};

// The transmittance table's x in texels for a ray from radius r (with
// c = top^2 - r^2, d_min = top - r and scale = (width - 1) / (d_max - d_min))
// in direction mu: glsl::DistanceToTopAtmosphereBoundary, then
// GetTransmittanceTextureUvFromRMu's x, in float.
inline float TransmittanceTableX(float r, float c, float d_min, float scale, float mu, float last) {
  const float r_mu = r * mu;
  const float s = std::sqrt(std::max(r_mu * r_mu + c, 0.0f));
  const float d = std::max(r_mu > 0.0f ? c / (r_mu + s) : s - r_mu, 0.0f);
  return ClampFloat((d - d_min) * scale, 0.0f, last);
}

class SunAtRadius {
 public:
  SunAtRadius(const AtmosphereParameters& params, const ChannelPlanes& transmittance)
      : params_(params), transmittance_(transmittance) {
    for (auto& row : row_) row.resize(transmittance.width);
  }

  void SetRadius(double r) {
    const AtmosphereParameters& p = params_;
    r = std::clamp(r, p.bottom_radius, p.top_radius);
    const double horizon_at_top = glsl::HorizonDistanceAtTop(p), rho = glsl::HorizonDistance(p, r);
    const double d_min = p.top_radius - r, d_max = rho + horizon_at_top;
    r_ = float(r);
    c_ = float((p.top_radius - r) * (p.top_radius + r));
    d_min_ = float(d_min);
    scale_ = d_max > d_min ? float((transmittance_.width - 1) / (d_max - d_min)) : 0.0f;
    int y0, y1;
    double fy;
    glsl::detail::LinearTaps(glsl::GetTextureCoordFromUnitRange(rho / horizon_at_top, transmittance_.height),
                             transmittance_.height, y0, y1, fy);
    // The two rows around the radius, blended once for all directions.
    const int width = transmittance_.width;
    const float weight = float(fy);
    for (int channel = 0; channel < 3; ++channel) {
      const float* a = transmittance_.channel[channel].data() + std::size_t(y0) * width;
      const float* b = transmittance_.channel[channel].data() + std::size_t(y1) * width;
      float* row = row_[channel].data();
#pragma omp simd
      for (int x = 0; x < width; ++x) row[x] = a[x] + weight * (b[x] - a[x]);
    }
    const double sin_horizon = p.bottom_radius / r;
    horizon_cosine_ = float(-std::sqrt(std::max(0.0, 1.0 - sin_horizon * sin_horizon)));
    half_disc_ = float(sin_horizon * p.sun_angular_radius);
  }

  // For `count` sun cosines: the optical depth per channel into tau[c][j]
  // and the visible fraction into visible[j].
  void Evaluate(const float* mu_s, int count, std::vector<float> (&tau)[3], float* visible) {
    const float r = r_, c = c_, d_min = d_min_, scale = scale_;
    const float horizon = horizon_cosine_, half_disc = half_disc_;
    const float last = float(transmittance_.width - 1);
    const int last_left = transmittance_.width - 2;
    if (int(left_.size()) < count) left_.resize(count), weight_.resize(count);
    int* left = left_.data();
    float* weight = weight_.data();
#pragma omp simd
    for (int j = 0; j < count; ++j) {
      const float x = TransmittanceTableX(r, c, d_min, scale, mu_s[j], last);
      left[j] = std::min(static_cast<int>(x), last_left);
      weight[j] = x - float(left[j]);
      visible[j] = SmoothstepFloat(-half_disc, half_disc, mu_s[j] - horizon);
    }
    for (int channel = 0; channel < 3; ++channel) {
      const float* row = row_[channel].data();
      float* out = tau[channel].data();
#pragma omp simd
      for (int j = 0; j < count; ++j) out[j] = row[left[j]] + weight[j] * (row[left[j] + 1] - row[left[j]]);
    }
  }

 private:
  const AtmosphereParameters& params_;
  const ChannelPlanes& transmittance_;  // optical depth
  std::vector<int> left_;               // per direction: the left tap along x
  std::vector<float> weight_;           // and the right one's weight
  std::vector<float> row_[3];           // per channel, the table interpolated to the radius
  float r_ = 0.0f, c_ = 0.0f, d_min_ = 0.0f, scale_ = 0.0f, horizon_cosine_ = 0.0f, half_disc_ = 0.0f;
};

// The same for points at different radii (each its own bilinear lookup):
// for the sub-intervals of the partly shadowed intervals of a ray, batched.
class SunAtPoints {
 public:
  SunAtPoints(const AtmosphereParameters& params, const ChannelPlanes& transmittance)
      : params_(params), transmittance_(transmittance) {}

  // For `count` points at radii r[l] with sun cosines mu_s[l]: the optical
  // depth per channel into tau[c][l] and the visible fraction into visible[l].
  void Evaluate(const float* r_in, const float* mu_s, int count, std::vector<float> (&tau)[3], float* visible) const {
    const AtmosphereParameters& p = params_;
    const float bottom = float(p.bottom_radius), top = float(p.top_radius);
    const float horizon_at_top = float(glsl::HorizonDistanceAtTop(p)), angular_radius = float(p.sun_angular_radius);
    const int width = transmittance_.width, height = transmittance_.height;
    const float last_x = float(width - 1), last_y = float(height - 1);
    const int last_left = width - 2, last_low = std::max(height - 2, 0);
    const float *plane0 = transmittance_.channel[0].data(), *plane1 = transmittance_.channel[1].data(),
                *plane2 = transmittance_.channel[2].data();
    float *tau0 = tau[0].data(), *tau1 = tau[1].data(), *tau2 = tau[2].data();
#pragma omp simd
    for (int l = 0; l < count; ++l) {
      const float r = ClampFloat(r_in[l], bottom, top);
      const float rho = std::sqrt(std::max((r - bottom) * (r + bottom), 0.0f));
      const float d_min = top - r, d_max = rho + horizon_at_top;
      const float scale = d_max > d_min ? last_x / (d_max - d_min) : 0.0f;
      const float x = TransmittanceTableX(r, (top - r) * (top + r), d_min, scale, mu_s[l], last_x);
      const float y = ClampFloat(rho / horizon_at_top * last_y, 0.0f, last_y);
      const int i = std::min(static_cast<int>(x), last_left), k = std::min(static_cast<int>(y), last_low);
      const float fx = x - float(i), fy = y - float(k);
      const int t00 = k * width + i, t10 = t00 + 1, t01 = std::min(k + 1, height - 1) * width + i, t11 = t01 + 1;
      const float a0 = plane0[t00] + fx * (plane0[t10] - plane0[t00]), b0 = plane0[t01] + fx * (plane0[t11] - plane0[t01]);
      const float a1 = plane1[t00] + fx * (plane1[t10] - plane1[t00]), b1 = plane1[t01] + fx * (plane1[t11] - plane1[t01]);
      const float a2 = plane2[t00] + fx * (plane2[t10] - plane2[t00]), b2 = plane2[t01] + fx * (plane2[t11] - plane2[t01]);
      tau0[l] = a0 + fy * (b0 - a0), tau1[l] = a1 + fy * (b1 - a1), tau2[l] = a2 + fy * (b2 - a2);
      const float sin_horizon = bottom / r;
      const float horizon = -std::sqrt(std::max(1.0f - sin_horizon * sin_horizon, 0.0f));
      const float half_disc = sin_horizon * angular_radius;
      visible[l] = SmoothstepFloat(-half_disc, half_disc, mu_s[l] - horizon);
    }
  }

 private:
  const AtmosphereParameters& params_;
  const ChannelPlanes& transmittance_;  // optical depth
};

// glsl::GetScatteringTextureUMuS in float, as the left tap and weight of the
// linear interpolation along mu_s (vectorisable).
class MuSCoordinate {
 public:
  explicit MuSCoordinate(const AtmosphereParameters& grid) {
    const double top = grid.top_radius, bottom = grid.bottom_radius;
    const double d_min = top - bottom, d_max = glsl::HorizonDistanceAtTop(grid);
    const double big_d = glsl::DistanceToTopAtmosphereBoundary(grid, bottom, grid.scattering_mu_s_min);
    bottom_ = float(bottom), c_ = float((top - bottom) * (top + bottom)), d_min_ = float(d_min);
    inverse_span_ = float(1.0 / (d_max - d_min)), inverse_a_ = float((d_max - d_min) / (big_d - d_min));
    last_ = float(grid.scattering_mu_s_size - 1), last_left_ = grid.scattering_mu_s_size - 2;
    scale_ = float((grid.scattering_mu_s_size - 1) / glsl::GetScatteringUnitMuS(grid, grid.scattering_mu_s_max));
  }
  // For `count` sun cosines: the position along the mu_s axis in texels
  // (in [0, size - 1]) split into a left tap (whose right neighbour exists)
  // and the weight of the right one.
  void Taps(const float* mu_s, int count, int* left, float* weight) const {
    const float bottom = bottom_, c = c_, d_min = d_min_, inverse_span = inverse_span_, inverse_a = inverse_a_;
    const float last = last_, scale = scale_;
    const int last_left = last_left_;
#pragma omp simd
    for (int j = 0; j < count; ++j) {
      const float r_mu = bottom * mu_s[j];
      const float s = std::sqrt(std::max(r_mu * r_mu + c, 0.0f));
      const float d = std::max(r_mu > 0.0f ? c / (r_mu + s) : s - r_mu, 0.0f);
      const float a = (d - d_min) * inverse_span;
      const float position = ClampFloat(std::max(1.0f - a * inverse_a, 0.0f) / (1.0f + a) * scale, 0.0f, last);
      const int i = std::min(static_cast<int>(position), last_left);
      left[j] = i;
      weight[j] = position - float(i);
    }
  }

 private:
  float bottom_ = 0.0f, c_ = 0.0f, d_min_ = 0.0f, inverse_span_ = 0.0f, inverse_a_ = 0.0f, last_ = 0.0f, scale_ = 0.0f;
  int last_left_ = 0;
};

// The incoming radiance at a point, sampled in a set of directions with
// their solid angles, and its mean over them weighted by a phase function
// around a view direction. The discrete phase weights are normalised to sum
// to one, so the quadrature neither creates nor loses energy for sharp lobes.
class PhaseWeightedRadiance {
 public:
  PhaseWeightedRadiance(const std::vector<vec3>& directions, const std::vector<vec3>& radiance,
                        const std::vector<double>& solid_angles) {
    const std::size_t n = directions.size();
    for (auto* v : {&x_, &y_, &z_, &r_, &g_, &b_, &w_}) v->resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const vec3& d = directions[i];
      const vec3& l = radiance[i];
      const double w = solid_angles[i];
      x_[i] = float(d.x), y_[i] = float(d.y), z_[i] = float(d.z);
      r_[i] = float(l.x), g_[i] = float(l.y), b_[i] = float(l.z), w_[i] = float(w);
      // Moments for the Rayleigh and isotropic phases, whose weighted sums
      // are quadratic forms of the view direction.
      const double dd[6] = {d.x * d.x, d.y * d.y, d.z * d.z, d.x * d.y, d.x * d.z, d.y * d.z};
      weight_ += w;
      sum_ += l * w;
      for (int j = 0; j < 6; ++j) {
        weight_moments_[j] += w * dd[j];
        moments_[j] += l * (w * dd[j]);
      }
    }
  }

  vec3 Mean(const PhaseFunction& phase, const vec3& view) const {
    switch (phase.kind) {
      case PhaseKind::kIsotropic:
        return weight_ > 0.0 ? sum_ / weight_ : vec3(0.0);
      case PhaseKind::kRayleigh: {
        // Phase proportional to 1 + (v.d)^2.
        const double vv[6] = {view.x * view.x,       view.y * view.y,       view.z * view.z,
                              2.0 * view.x * view.y, 2.0 * view.x * view.z, 2.0 * view.y * view.z};
        vec3 sum = sum_;
        double weight = weight_;
        for (int j = 0; j < 6; ++j) {
          sum += moments_[j] * vv[j];
          weight += weight_moments_[j] * vv[j];
        }
        return weight > 0.0 ? sum / weight : vec3(0.0);
      }
      case PhaseKind::kHenyeyGreenstein:
        return LobeMean(phase.g, false, view);
      case PhaseKind::kCornetteShanks:
        return LobeMean(phase.g, true, view);
    }
    return vec3(0.0);
  }

 private:
  // Henyey-Greenstein, times (1 + cos^2) for Cornette-Shanks, without their
  // constant factors (they cancel in the normalised mean); a float loop the
  // compiler vectorises.
  vec3 LobeMean(double g, bool cornette_shanks, const vec3& view) const {
    const float vx = float(view.x), vy = float(view.y), vz = float(view.z);
    const float a = float(1.0 + g * g), b = float(2.0 * g);
    float sr = 0.0f, sg = 0.0f, sb = 0.0f, sw = 0.0f;
    const std::size_t n = x_.size();
#pragma omp simd reduction(+ : sr, sg, sb, sw)
    for (std::size_t i = 0; i < n; ++i) {
      const float c = vx * x_[i] + vy * y_[i] + vz * z_[i];
      const float denominator = a - b * c;
      float w = w_[i] / (denominator * std::sqrt(denominator));
      if (cornette_shanks) w *= 1.0f + c * c;
      sr += w * r_[i];
      sg += w * g_[i];
      sb += w * b_[i];
      sw += w;
    }
    return sw > 0.0f ? vec3(sr, sg, sb) / double(sw) : vec3(0.0);
  }

  std::vector<float> x_, y_, z_, r_, g_, b_, w_;
  double weight_ = 0.0;
  vec3 sum_{0.0};
  double weight_moments_[6] = {};
  vec3 moments_[6] = {vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0)};
};

class Baker {
 public:
  Baker(const Atmosphere& atmosphere, const BakeSettings& settings)
      : medium_(atmosphere),
        settings_(settings),
        params_(MakeAtmosphereParameters(atmosphere, settings)),
        atmosphere_grid_(AtmosphereGrid(atmosphere, settings)),
        orders_grid_(HigherOrderGrid(atmosphere_grid_, settings.higher_order_divisor)) {}

  LutSet Run(BakeReport* report, const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot);

 private:
  template <typename F>
  void Phase(const std::string& name, F&& work);

  // Single scattering on a grid, Rayleigh (the other groups) and Mie apart,
  // both phase free.
  struct SingleScattering {
    Texture rayleigh, mie;
  };

  void ComputeTransmittance();
  // Single scattering on `grid`, with `ray_samples` intervals per ray.
  SingleScattering ComputeSingleScattering(const AtmosphereParameters& grid, int ray_samples) const;
  // Single scattering of the texels of one ray of `grid` (mu index y, r
  // index z), n intervals, into `out`. `columns`: the grid's sun
  // directions; `transmittance`: the transmittance table's channels.
  void SingleScatteringAlongRay(const AtmosphereParameters& grid, int n, int y, int z, const SunColumns& columns,
                                const ChannelPlanes& transmittance, SingleScattering& out) const;
  // Single scattering over interval k of a ray for one sun direction, in
  // double, for the intervals SingleScatteringAlongRay does not vectorise:
  // optically thick, partly shadowed or crossed by the shadow edge.
  // phase_ratio: per group, its phase over the Rayleigh phase at nu.
  void SingleScatteringInterval(const RaySamples& ray, int k, double mu_s, double nu, const double* phase_ratio,
                                Spectrum& rayleigh_sum, Spectrum& mie_sum) const;
  void ComputeScatteringDensity(int order);
  void ComputeIndirectIrradiance(int order);
  // The light of the orders whose scattering density (per unit scattering
  // coefficient, on the grid of `density_grid`) is `density`, arriving at
  // every texel of a table on the grid `grid`: the density integrated along
  // each texel's ray.
  Texture GatherAlongRays(const AtmosphereParameters& grid, const Texture& density,
                          const AtmosphereParameters& density_grid) const;
  // Whether the table covers less than the whole atmosphere (a scene's bake):
  // its grid is then not the one the orders are computed on.
  bool TableRestricted() const { return settings_.scattering_range.has_value(); }
  // Whether the orders are gathered on another grid than the table's, so
  // that the table's higher orders come from one gather of their summed
  // densities at the end.
  bool GatherAtEnd() const { return settings_.higher_order_divisor > 1 || TableRestricted(); }
  // Single scattering on the atmosphere's grid, the light of order 1.
  const SingleScattering& GridSingle() const { return TableRestricted() ? grid_single_ : single_; }
  // The scattering table: single Rayleigh plus the higher orders.
  Texture ScatteringTable() const;
  // MultipleScatteringPackingFactor per nu index of a grid.
  static std::vector<double> PackingFactors(const AtmosphereParameters& grid);
  // Mean over the texels of a table on a scattering grid, each times the
  // factor of its nu index (1 where `per_nu` is empty).
  static Spectrum TableMean(const Texture& table, const AtmosphereParameters& grid, const std::vector<double>& per_nu);
  // The tables as they stand, copied (for BakeOrderSnapshot) or moved out
  // (the result).
  LutSet AssembleTables(Texture transmittance, Texture irradiance, Texture scattering, Texture single_mie) const;
  double PhaseSecondsSoFar() const;

  // The ray of a scattering texel row, sampled at n + 1 points.
  RaySamples SampleRay(const AtmosphereParameters& grid, int mu_index, int r_index, int n) const;
  // The table holds single Rayleigh scattering phase free and the higher
  // orders divided by the Rayleigh phase, which the runtime multiplies back
  // with the query's nu. The division uses the nu of the texel's slice, not
  // the texel's clamped nu: where (mu, mu_s) allow a narrow range of nu (near
  // the zenith, where the mu axis is coarse at low altitude), every slice is
  // clamped to nearly the same geometry, and dividing by the phase at that
  // clamped nu and multiplying by the phase at the query's nu would scale the
  // smooth higher orders by up to P(1)/P(0) = 2.
  static double MultipleScatteringPackingFactor(const AtmosphereParameters& grid, int nu_index) {
    return 1.0 /
           glsl::RayleighPhaseFunction(GetScatteringTexel(grid, nu_index * grid.scattering_mu_s_size, 0, 0).grid_nu);
  }

  // Radiance of scattering order `order` arriving at radius r from the
  // directions with zenith cosine mu, with the sun at mu_s, excluding light
  // reflected by the ground, as a function of nu (the cosine between the
  // direction and the sun): the table lookups that do not depend on nu are
  // done once, for all the azimuths of a ring of directions.
  class IncidentAlongNu {
   public:
    IncidentAlongNu(const Baker& baker, int order, double r, double mu, double mu_s, bool intersects_ground);
    vec3 At(double nu) const;

   private:
    const AtmosphereParameters& params_;
    bool single_;  // order 1: Rayleigh and Mie tables, phases applied here
    int nu_size_ = 0;
    std::vector<vec3> first_, second_;  // per nu slice 0 ... nu_size
  };
  // Irradiance of order `order` on the ground where the sun is at mu_s.
  vec3 GroundIrradiance(int order, double mu_s) const;
  vec3 DirectIrradiance(double r, double mu_s) const;

  Medium medium_;
  BakeSettings settings_;
  AtmosphereParameters params_;  // the tables'
  // The grid over the whole atmosphere that each order's scattering density
  // lives on: the table's, or for a table restricted to a scene's ranges
  // one with BakeSettings::ScatteringRange's sizes.
  AtmosphereParameters atmosphere_grid_;
  // The grid of each order's radiance (BakeSettings::higher_order_divisor).
  AtmosphereParameters orders_grid_;
  BakeReport report_;
  BakeProgress progress_;

  Texture transmittance_;
  Texture irradiance_;
  SingleScattering single_;       // on the table's grid
  SingleScattering grid_single_;  // on atmosphere_grid_ where the table is restricted
  Texture delta_multiple_;        // radiance of the latest order >= 2, on orders_grid_
  // J of the current order per unit scattering coefficient, on atmosphere_grid_.
  Texture scattering_density_;
  // Sum over the orders >= 2 so far, and their tail, of their radiance, or
  // of their J where GatherAtEnd(); on atmosphere_grid_.
  Texture higher_orders_;
  Texture delta_irradiance_;      // ground irradiance of the latest order >= 2
};

template <typename F>
void Baker::Phase(const std::string& name, F&& work) {
  auto start = std::chrono::steady_clock::now();
  work();
  BakeTiming timing{name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  report_.timings.push_back(timing);
  if (progress_) progress_(timing);
}

LutSet Baker::AssembleTables(Texture transmittance, Texture irradiance, Texture scattering,
                             Texture single_mie) const {
  LutSet result;
  result.atmosphere = medium_.atmosphere();
  result.settings = settings_;
  result.orders_used = report_.orders_used;
  result.parameters = params_;
  result.transmittance = std::move(transmittance);
  result.irradiance = std::move(irradiance);
  if (params_.single_mie_in_scattering_alpha == 1) {
    for (size_t i = 0; i < scattering.texels.size(); i += 4) scattering.texels[i + 3] = single_mie.texels[i];
  } else {
    result.single_mie_scattering = std::move(single_mie);
  }
  result.scattering = std::move(scattering);
  return result;
}

double Baker::PhaseSecondsSoFar() const {
  double seconds = 0.0;
  for (const BakeTiming& t : report_.timings) seconds += t.seconds;
  return seconds;
}

LutSet Baker::Run(BakeReport* report, const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot) {
  progress_ = progress;
  auto snapshot = [&](int order) {
    if (order_snapshot) {
      LutSet tables = AssembleTables(transmittance_, irradiance_, ScatteringTable(), single_.mie);
      tables.settings.orders = order;  // exactly these orders, no tail
      tables.settings.extrapolate_tail = false;
      order_snapshot(order, tables, PhaseSecondsSoFar());
    }
  };
  auto start = std::chrono::steady_clock::now();
  const BakeSettings& s = settings_;
  transmittance_ = Texture(s.transmittance_width, s.transmittance_height);
  irradiance_ = Texture(s.irradiance_width, s.irradiance_height);

  Phase("transmittance", [&] { ComputeTransmittance(); });
  Phase("single scattering", [&] { single_ = ComputeSingleScattering(params_, s.ray_samples); });
  if (s.orders != 1 && TableRestricted()) {
    // It feeds only the next order, through an integral over the sphere.
    Phase("single scattering, whole atmosphere", [&] {
      grid_single_ = ComputeSingleScattering(atmosphere_grid_, s.scattering_range->atmosphere_ray_samples);
    });
  }
  if (s.orders != 1) {  // 0 = auto
    scattering_density_ = ScatteringGridTexture(atmosphere_grid_);
    higher_orders_ = ScatteringGridTexture(atmosphere_grid_);
    delta_irradiance_ = Texture(s.irradiance_width, s.irradiance_height);
  }
  report_.orders_used = 1;
  snapshot(1);
  report_.remaining_error = -1.0;  // unknown until two orders can be compared
  const bool auto_orders = s.orders == 0;
  OrderConvergence convergence;
  // Convergence is measured on means over the tables (each order's on its own grid).
  OrderSums sums;
  sums.table = TableMean(GridSingle().rayleigh, atmosphere_grid_, {});
  const std::vector<double> orders_packing = PackingFactors(orders_grid_);
  const bool gather_at_end = GatherAtEnd();
  for (int order = 2; order <= (auto_orders ? s.max_orders : s.orders); ++order) {
    std::string prefix = "order " + std::to_string(order) + ": ";
    Phase(prefix + "scattering density", [&] { ComputeScatteringDensity(order); });
    Phase(prefix + "indirect irradiance", [&] { ComputeIndirectIrradiance(order - 1); });
    // On the table's grid the orders themselves are summed; on a coarser
    // one, their densities, for the final gather.
    const Texture& newest = gather_at_end ? scattering_density_ : delta_multiple_;
    Phase(prefix + "multiple scattering", [&] {
      delta_multiple_ = GatherAlongRays(orders_grid_, scattering_density_, atmosphere_grid_);
      AddScaled(newest, Spectrum(1.0), higher_orders_);
    });
    report_.orders_used = order;
    sums.newest = TableMean(delta_multiple_, orders_grid_, orders_packing);
    sums.table += sums.newest;
    convergence.Add(sums);
    report_.order_ratio = convergence.Ratio();
    report_.remaining_error = convergence.RemainingWithoutTail();
    snapshot(order);
    if (auto_orders && convergence.NewestIsZero()) break;
    // Auto: stop once the tail is known well enough. A fixed count: add the
    // tail after its last order, if the orders decay geometrically by then.
    std::optional<Spectrum> tail = convergence.TailFactor();
    const bool add_tail = auto_orders ? tail && convergence.TailError() < s.order_tolerance
                                      : order == s.orders && s.extrapolate_tail && tail && !convergence.NewestIsZero();
    if (add_tail) {
      // The orders not computed: the newest order's density and irradiance
      // times q / (1 - q) per channel.
      Phase("extrapolated orders", [&] {
        AddScaled(newest, *tail, higher_orders_);
        AddScaled(delta_irradiance_, *tail, irradiance_);
      });
      report_.extrapolated_tail = convergence.RelativeTail();
      report_.remaining_error = convergence.TailError();
      break;
    }
  }
  Texture scattering;
  if (gather_at_end) {
    Phase("gather higher orders", [&] { scattering = ScatteringTable(); });
  } else {
    scattering = ScatteringTable();
  }

  LutSet result = AssembleTables(std::move(transmittance_), std::move(irradiance_), std::move(scattering),
                                 std::move(single_.mie));
  report_.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = report_;
  return result;
}

Texture Baker::ScatteringTable() const {
  Texture table = single_.rayleigh;
  if (report_.orders_used < 2) return table;
  const Texture higher = GatherAtEnd() ? GatherAlongRays(params_, higher_orders_, atmosphere_grid_) : higher_orders_;
  const int mu_s_size = params_.scattering_mu_s_size;
  const std::vector<double> packing = PackingFactors(params_);
  ForEachRow(table, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      const double factor = packing[(i - first) / 4 / mu_s_size];
      for (int c = 0; c < 3; ++c) table.texels[i + c] += float(higher.texels[i + c] * factor);
    }
  });
  return table;
}

std::vector<double> Baker::PackingFactors(const AtmosphereParameters& grid) {
  std::vector<double> factors(grid.scattering_nu_size);
  for (int nu = 0; nu < grid.scattering_nu_size; ++nu) factors[nu] = MultipleScatteringPackingFactor(grid, nu);
  return factors;
}

Spectrum Baker::TableMean(const Texture& table, const AtmosphereParameters& grid, const std::vector<double>& per_nu) {
  const int mu_s_size = grid.scattering_mu_s_size;
  // Per row, then the rows in order: the same sum whatever the threads do.
  std::vector<Spectrum> row_sums(std::size_t(table.height) * table.depth, Spectrum(0.0));
  ForEachRow(table, [&](int row, std::size_t first, std::size_t end) {
    Spectrum sum(0.0);
    for (std::size_t i = first; i < end; i += 4) {
      const double factor = per_nu.empty() ? 1.0 : per_nu[(i - first) / 4 / mu_s_size];
      for (int c = 0; c < 3; ++c) sum[c] += table.texels[i + c] * factor;
    }
    row_sums[row] = sum;
  });
  Spectrum sum(0.0);
  for (const Spectrum& row_sum : row_sums) sum += row_sum;
  return sum / double(table.texels.size() / 4);
}

void Baker::ComputeTransmittance() {
  const int width = transmittance_.width, height = transmittance_.height;
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      double r, mu;
      glsl::GetRMuFromTransmittanceTextureUv(params_, glsl::vec2((x + 0.5) / width, (y + 0.5) / height), r, mu);
      double d = glsl::DistanceToTopAtmosphereBoundary(params_, r, mu);
      Spectrum tau = medium_.OpticalDepth(r, mu, d, settings_.transmittance_samples);
      transmittance_.Store(x, y, 0, vec4(tau, 0.0));
    }
  });
}

RaySamples Baker::SampleRay(const AtmosphereParameters& grid, int mu_index, int r_index, int n) const {
  RaySamples ray;
  const ScatteringTexel texel = GetScatteringTexel(grid, 0, mu_index, r_index);
  ray.r = texel.r, ray.mu = texel.mu, ray.intersects_ground = texel.ray_intersects_ground;
  double d = glsl::DistanceToNearestAtmosphereBoundary(params_, ray.r, ray.mu, ray.intersects_ground);
  const int constituents = medium_.constituent_count();
  const int groups = static_cast<int>(medium_.groups().size());
  ray.t = RayDistances(d, n);
  ray.radius.resize(n + 1);
  ray.optical_depth.assign(n + 1, Spectrum(0.0));
  ray.extinction.resize(n + 1);
  ray.scattering.assign(groups, std::vector<Spectrum>(n + 1));
  std::vector<double> densities(constituents), previous(constituents);
  for (int k = 0; k <= n; ++k) {
    double t = ray.t[k];
    ray.radius[k] = glsl::RadiusAtDistance(params_, ray.r, ray.mu, t);
    medium_.Densities(ray.radius[k] - params_.bottom_radius, densities.data());
    for (int g = 0; g < groups; ++g) ray.scattering[g][k] = medium_.GroupScattering(g, densities.data());
    ray.extinction[k] = medium_.Extinction(densities.data());
    if (k > 0) {
      Spectrum tau = ray.optical_depth[k - 1];
      for (int c = 0; c < constituents; ++c) {
        tau += medium_.atmosphere().constituents[c].Extinction() *
               ExponentialTrapezoid(previous[c], densities[c], ray.t[k] - ray.t[k - 1]);
      }
      ray.optical_depth[k] = tau;
    }
    std::swap(densities, previous);
  }
  return ray;
}

Baker::SingleScattering Baker::ComputeSingleScattering(const AtmosphereParameters& grid, int ray_samples) const {
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const ChannelPlanes transmittance(transmittance_);
  const SunColumns columns(grid);
  SingleScattering result{ScatteringGridTexture(grid), ScatteringGridTexture(grid)};
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    SingleScatteringAlongRay(grid, ray_samples, ray_index % mu_size, ray_index / mu_size, columns, transmittance,
                             result);
  });
  return result;
}

void Baker::SingleScatteringAlongRay(const AtmosphereParameters& grid, int n, int y, int z, const SunColumns& columns,
                                     const ChannelPlanes& transmittance, SingleScattering& out) const {
  const int groups = static_cast<int>(medium_.groups().size());
  const int mie = medium_.mie_group();
  const RaySamples ray = SampleRay(grid, y, z, n);
  const SunDirections directions = RaySunDirections(columns, ray.mu);
  const int count = static_cast<int>(directions.mu_s.size());

  // Per group, channel and sample, the factors shared by all directions:
  // the scattering coefficient times the view's transmittance, and the log
  // of its ratio between neighbouring samples (so that the exponential
  // trapezoid needs no logarithm per direction, and an end that underflows
  // in float still decays at its true rate), where both ends scatter.
  const std::size_t per_ray = std::size_t(groups) * 3 * (n + 1);
  std::vector<double> base_double(per_ray);  // (for the sub-intervals below, where float could underflow)
  std::vector<float> base(per_ray), log_ratio(per_ray);
  std::vector<char> has_ratio(per_ray);
  auto at = [&](int g, int c, int k) { return (std::size_t(g) * 3 + c) * (n + 1) + k; };
  for (int g = 0; g < groups; ++g) {
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k <= n; ++k) {
        base_double[at(g, c, k)] = ray.scattering[g][k][c] * std::exp(-ray.optical_depth[k][c]);
        base[at(g, c, k)] = float(base_double[at(g, c, k)]);
      }
      for (int k = 0; k < n; ++k) {
        const double a = ray.scattering[g][k][c], b = ray.scattering[g][k + 1][c];
        const bool positive = a > 0.0 && b > 0.0;
        has_ratio[at(g, c, k)] = positive;
        log_ratio[at(g, c, k)] =
            positive ? float(std::log(b / a) - (ray.optical_depth[k + 1][c] - ray.optical_depth[k][c])) : 0.0f;
      }
    }
  }
  // The table divides out the Rayleigh phase; the other groups' phases
  // (all but the Mie group's, which has its own table) are applied here.
  std::vector<std::vector<float>> phase_ratio(groups, std::vector<float>(count, 1.0f));
  std::vector<std::vector<double>> phase_ratio_double(count, std::vector<double>(groups, 1.0));
  for (int g = 0; g < groups; ++g) {
    if (g == mie) continue;
    for (int j = 0; j < count; ++j) {
      const double nu = directions.nu[j];
      phase_ratio_double[j][g] = medium_.groups()[g].phase.Evaluate(nu) / glsl::RayleighPhaseFunction(nu);
      phase_ratio[g][j] = float(phase_ratio_double[j][g]);
    }
  }

  // Per direction: the sun's optical depth, transmittance and visible
  // fraction at the previous and the current sample, and the sums.
  struct SunState {
    std::vector<float> tau[3], transmittance[3], visible;
    explicit SunState(int count) : visible(count) {
      for (int c = 0; c < 3; ++c) tau[c].resize(count), transmittance[c].resize(count);
    }
  };
  SunState previous(count), current(count);
  // The partly shadowed intervals' (interval, direction) pairs, with the
  // sunlight at their ends, and per interval, group and channel the base at
  // the ends of its sub-intervals.
  struct ShadowedPieces {
    std::vector<int> direction, interval;
    std::vector<double> mu_s, nu;
    std::vector<float> sun_start[3], sun_end[3];
  } pieces;
  std::vector<float> piece_base(std::size_t(n) * groups * 3 * (kShadowEdgeSubdivisions + 1));
  std::vector<float> sums[2][3];  // [0: Rayleigh table, 1: Mie table][channel]
  for (auto& kind : sums) {
    for (auto& channel : kind) channel.assign(count, 0.0f);
  }
  std::vector<float> mu_s(directions.mu_s.begin(), directions.mu_s.end()), nu(directions.nu.begin(), directions.nu.end());
  std::vector<float> mu_s_k(count);
  std::vector<char> lit(count);
  std::vector<int> shadowed, thick;
  SunAtRadius sun(params_, transmittance);
  for (int k = 0; k <= n; ++k) {
    // The sun's cosine at the sample: (r mu_s + t nu) / r_k.
    const float from_mu_s = float(ray.r / ray.radius[k]), from_nu = float(ray.t[k] / ray.radius[k]);
#pragma omp simd
    for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
    sun.SetRadius(ray.radius[k]);
    sun.Evaluate(mu_s_k.data(), count, current.tau, current.visible.data());
    for (int c = 0; c < 3; ++c) {
      const float* tau = current.tau[c].data();
      float* transmittance = current.transmittance[c].data();
#pragma omp simd
      for (int j = 0; j < count; ++j) transmittance[j] = ExpFloat(-tau[j]);
    }
    if (k > 0) {
      // Fully lit, optically thin intervals: the exponential trapezoid of
      // each group's integrand, vectorised over the directions.
      const int interval = k - 1;
      const float h = float(ray.t[k] - ray.t[interval]);
      const bool thin = ray.ThinInterval(interval);
      // The rest, where any of it is lit: optically thin but partly
      // shadowed (the shadow edge crosses the interval, or the sun's disc is
      // partly hidden), or thick.
      shadowed.clear(), thick.clear();
      for (int j = 0; j < count; ++j) {
        const bool fully_lit = previous.visible[j] == 1.0f && current.visible[j] == 1.0f;
        lit[j] = thin && fully_lit;
        if (!lit[j] && (previous.visible[j] > 0.0f || current.visible[j] > 0.0f)) (thin ? shadowed : thick).push_back(j);
      }
      for (int g = 0; g < groups; ++g) {
        for (int c = 0; c < 3; ++c) {
          const float base_a = base[at(g, c, interval)], base_b = base[at(g, c, k)];
          const float ratio = log_ratio[at(g, c, interval)];
          const bool exponential = has_ratio[at(g, c, interval)];
          const float *sun_a = previous.transmittance[c].data(), *sun_b = current.transmittance[c].data();
          const float *tau_a = previous.tau[c].data(), *tau_b = current.tau[c].data();
          const float* phase = phase_ratio[g].data();
          float* sum = sums[g == mie ? 1 : 0][c].data();
          // (Two loops: a choice between them inside one keeps it from vectorising.)
          if (exponential) {
#pragma omp simd
            for (int j = 0; j < count; ++j) {
              const float fa = base_a * sun_a[j], fb = base_b * sun_b[j];
              const float integral = ExponentialTrapezoidFloat(fa, fb, ratio - (tau_b[j] - tau_a[j]), h);
              sum[j] += lit[j] ? integral * phase[j] : 0.0f;
            }
          } else {
#pragma omp simd
            for (int j = 0; j < count; ++j) {
              const float integral = 0.5f * h * (base_a * sun_a[j] + base_b * sun_b[j]);
              sum[j] += lit[j] ? integral * phase[j] : 0.0f;
            }
          }
        }
      }
      if (!shadowed.empty()) {
        // Integrated after the last sample, all of the ray's at once.
        for (int g = 0; g < groups; ++g) {
          for (int c = 0; c < 3; ++c) {
            float* ends = &piece_base[((std::size_t(interval) * groups + g) * 3 + c) * (kShadowEdgeSubdivisions + 1)];
            if (has_ratio[at(g, c, interval)]) {
              const double step = std::exp(double(log_ratio[at(g, c, interval)]) / kShadowEdgeSubdivisions);
              double value = base_double[at(g, c, interval)];
              for (int i = 0; i <= kShadowEdgeSubdivisions; ++i, value *= step) ends[i] = float(value);
            } else {
              const float base_a = base[at(g, c, interval)], base_b = base[at(g, c, k)];
              for (int i = 0; i <= kShadowEdgeSubdivisions; ++i) {
                ends[i] = base_a + (base_b - base_a) * float(i) / kShadowEdgeSubdivisions;
              }
            }
          }
        }
        for (int j : shadowed) {
          pieces.direction.push_back(j);
          pieces.interval.push_back(interval);
          pieces.mu_s.push_back(directions.mu_s[j]), pieces.nu.push_back(directions.nu[j]);
          for (int c = 0; c < 3; ++c) {
            pieces.sun_start[c].push_back(previous.transmittance[c][j] * previous.visible[j]);
            pieces.sun_end[c].push_back(current.transmittance[c][j] * current.visible[j]);
          }
        }
      }
      for (int j : thick) {
        Spectrum rayleigh(0.0), mie_sum(0.0);
        SingleScatteringInterval(ray, interval, directions.mu_s[j], directions.nu[j], phase_ratio_double[j].data(),
                                 rayleigh, mie_sum);
        for (int c = 0; c < 3; ++c) sums[0][c][j] += float(rayleigh[c]), sums[1][c][j] += float(mie_sum[c]);
      }
    }
    std::swap(previous, current);
  }

  // The partly shadowed intervals: the sun's transmittance times its
  // visible fraction on kShadowEdgeSubdivisions sub-intervals, the
  // scattering coefficient times the view's transmittance geometric between
  // the samples (linear if an end does not scatter), and the trapezoid rule
  // on the sub-intervals; vectorised over all of the ray's such intervals
  // and directions.
  const int pair_count = static_cast<int>(pieces.direction.size());
  if (pair_count > 0) {
    constexpr int sub = kShadowEdgeSubdivisions;
    SunState start(pair_count), end(pair_count);
    for (int c = 0; c < 3; ++c) start.transmittance[c] = pieces.sun_start[c];
    std::vector<float> piece_sums[2][3], radius(pair_count), mu_s_t(pair_count), half_piece(pair_count);
    for (auto& kind : piece_sums) {
      for (auto& channel : kind) channel.assign(pair_count, 0.0f);
    }
    std::vector<double> t_start(pair_count), length(pair_count);
    for (int l = 0; l < pair_count; ++l) {
      const int interval = pieces.interval[l];
      t_start[l] = ray.t[interval], length[l] = ray.t[interval + 1] - ray.t[interval];
      half_piece[l] = float(0.5 * length[l] / sub);
    }
    const double r = ray.r, r_mu = ray.r * ray.mu;
    const SunAtPoints sun_at_points(params_, transmittance);
    for (int i = 1; i <= sub; ++i) {
      if (i < sub) {
        const double fraction = double(i) / sub;
#pragma omp simd
        for (int l = 0; l < pair_count; ++l) {
          // In double: the visible fraction changes within a fraction of a
          // metre in altitude near the ground.
          const double t = t_start[l] + fraction * length[l];
          const double r_t = std::sqrt(std::max(t * t + 2.0 * r_mu * t + r * r, 0.0));
          radius[l] = float(r_t);
          mu_s_t[l] = float(std::max(-1.0, std::min((r * pieces.mu_s[l] + t * pieces.nu[l]) / r_t, 1.0)));
        }
        sun_at_points.Evaluate(radius.data(), mu_s_t.data(), pair_count, end.tau, end.visible.data());
        for (int c = 0; c < 3; ++c) {
          const float *tau = end.tau[c].data(), *visible = end.visible.data();
          float* sunlight = end.transmittance[c].data();
#pragma omp simd
          for (int l = 0; l < pair_count; ++l) sunlight[l] = ExpFloat(-tau[l]) * visible[l];
        }
      } else {
        for (int c = 0; c < 3; ++c) end.transmittance[c] = pieces.sun_end[c];
      }
      for (int g = 0; g < groups; ++g) {
        for (int c = 0; c < 3; ++c) {
          const float *sun_a = start.transmittance[c].data(), *sun_b = end.transmittance[c].data();
          const float* phase = phase_ratio[g].data();
          float* sum = piece_sums[g == mie ? 1 : 0][c].data();
          const int stride = sub + 1;
#pragma omp simd
          for (int l = 0; l < pair_count; ++l) {
            const float* ends = &piece_base[((std::size_t(pieces.interval[l]) * groups + g) * 3 + c) * stride];
            sum[l] += half_piece[l] * (ends[i - 1] * sun_a[l] + ends[i] * sun_b[l]) * phase[pieces.direction[l]];
          }
        }
      }
      std::swap(start, end);
    }
    for (int l = 0; l < pair_count; ++l) {
      for (int kind = 0; kind < 2; ++kind) {
        for (int c = 0; c < 3; ++c) sums[kind][c][pieces.direction[l]] += piece_sums[kind][c][l];
      }
    }
  }

  for (int x = 0; x < int(directions.of_texel.size()); ++x) {
    const int j = directions.of_texel[x];
    const vec3 rayleigh(sums[0][0][j], sums[0][1][j], sums[0][2][j]), mie_sum(sums[1][0][j], sums[1][1][j], sums[1][2][j]);
    out.rayleigh.Store(x, y, z, vec4(rayleigh * params_.solar_irradiance, 0.0));
    out.mie.Store(x, y, z, vec4(mie_sum * params_.solar_irradiance, 0.0));
  }
}

void Baker::SingleScatteringInterval(const RaySamples& ray, int k, double mu_s, double nu, const double* phase_ratio,
                                     Spectrum& rayleigh_sum, Spectrum& mie_sum) const {
  const int groups = static_cast<int>(medium_.groups().size());
  const int mie = medium_.mie_group();
  const glsl::sampler2D transmittance{&transmittance_};
  std::vector<double> densities(medium_.constituent_count());
  std::vector<Spectrum> scattering(groups);
  // Scattered light at distance t along the ray, per kind of table.
  auto sample = [&](double t, double r_t, const Spectrum& optical_depth, const Spectrum& extinction,
                    RayIntegrand& rayleigh_out, RayIntegrand& mie_out) {
    double mu_s_t = glsl::ClampCosine((ray.r * mu_s + t * nu) / r_t);
    double visible = glsl::SunVisibleFraction(params_, r_t, mu_s_t);
    Spectrum tau = glsl::GetOpticalDepthToTopAtmosphereBoundary(params_, transmittance, r_t, mu_s_t);
    Spectrum other(0.0);
    for (int g = 0; g < groups; ++g) {
      if (g != mie) other += scattering[g] * phase_ratio[g];
    }
    Spectrum attenuation = glm::exp(-(optical_depth + tau));
    Spectrum rayleigh_source = other * visible, mie_source = mie >= 0 ? scattering[mie] * visible : Spectrum(0.0);
    rayleigh_out = RayIntegrand{rayleigh_source, optical_depth, tau, extinction, rayleigh_source * attenuation};
    mie_out = RayIntegrand{mie_source, optical_depth, tau, extinction, mie_source * attenuation};
    return visible;
  };
  auto sample_at = [&](int i, RayIntegrand& rayleigh_out, RayIntegrand& mie_out) {
    for (int g = 0; g < groups; ++g) scattering[g] = ray.scattering[g][i];
    return sample(ray.t[i], ray.radius[i], ray.optical_depth[i], ray.extinction[i], rayleigh_out, mie_out);
  };
  const double h = ray.t[k + 1] - ray.t[k];
  RayIntegrand rayleigh_a, mie_a, rayleigh_b, mie_b;
  const double visible_a = sample_at(k, rayleigh_a, mie_a), visible_b = sample_at(k + 1, rayleigh_b, mie_b);
  if (visible_a == visible_b) {
    rayleigh_sum += IntegrateInterval(rayleigh_a, rayleigh_b, h);
    mie_sum += IntegrateInterval(mie_a, mie_b, h);
    return;
  }
  // The planet's shadow edge crosses this interval: the integrand switches
  // on or off within it, so subdivide it.
  const int pieces = kShadowEdgeSubdivisions;
  const double piece = h / pieces;
  RayIntegrand previous_rayleigh = rayleigh_a, previous_mie = mie_a;
  for (int i = 1; i <= pieces; ++i) {
    RayIntegrand next_rayleigh = rayleigh_b, next_mie = mie_b;
    if (i < pieces) {
      double f = double(i) / pieces;
      double t = ray.t[k] + f * h;
      double r_t = glsl::RadiusAtDistance(params_, ray.r, ray.mu, t);
      medium_.Densities(r_t - params_.bottom_radius, densities.data());
      for (int g = 0; g < groups; ++g) scattering[g] = medium_.GroupScattering(g, densities.data());
      Spectrum optical_depth = glm::mix(ray.optical_depth[k], ray.optical_depth[k + 1], f);
      sample(t, r_t, optical_depth, medium_.Extinction(densities.data()), next_rayleigh, next_mie);
    }
    rayleigh_sum += IntegrateInterval(previous_rayleigh, next_rayleigh, piece);
    mie_sum += IntegrateInterval(previous_mie, next_mie, piece);
    previous_rayleigh = next_rayleigh, previous_mie = next_mie;
  }
}

vec3 Baker::DirectIrradiance(double r, double mu_s) const {
  // Cosine factor averaged over the sun's disc when it straddles the horizon.
  double alpha = params_.sun_angular_radius;
  double cosine = mu_s < -alpha ? 0.0 : (mu_s > alpha ? mu_s : (mu_s + alpha) * (mu_s + alpha) / (4.0 * alpha));
  return params_.solar_irradiance *
         glsl::GetTransmittanceToTopAtmosphereBoundary(params_, glsl::sampler2D{&transmittance_}, r, mu_s) * cosine;
}

vec3 Baker::GroundIrradiance(int order, double mu_s) const {
  if (order == 1) return DirectIrradiance(params_.bottom_radius, mu_s);
  return glsl::GetIrradiance(params_, glsl::sampler2D{&delta_irradiance_}, params_.bottom_radius, mu_s);
}

Baker::IncidentAlongNu::IncidentAlongNu(const Baker& baker, int order, double r, double mu, double mu_s,
                                        bool intersects_ground)
    : params_(baker.params_), single_(order == 1) {
  const AtmosphereParameters& grid = single_ ? baker.atmosphere_grid_ : baker.orders_grid_;
  nu_size_ = grid.scattering_nu_size;
  // glsl::GetScattering's lookups of the nu slices 0 ... nu_size (the last
  // clamped to the edge, as the texture unit does), which nu only blends.
  const vec4 uvwz = glsl::GetScatteringTextureUvwzFromRMuMuSNu(grid, r, mu, mu_s, 0.0, intersects_ground);
  auto slices = [&](const Texture& table, std::vector<vec3>& out) {
    for (int slice = 0; slice <= nu_size_; ++slice) {
      const glsl::vec3 uvw((slice + uvwz.y) / nu_size_, uvwz.z, uvwz.w);
      out.push_back(vec3(glsl::texture(glsl::sampler3D{&table}, uvw)));
    }
  };
  if (single_) {
    slices(baker.GridSingle().rayleigh, first_);
    slices(baker.GridSingle().mie, second_);
  } else {
    slices(baker.delta_multiple_, first_);
  }
}

vec3 Baker::IncidentAlongNu::At(double nu) const {
  // glsl::GetScattering's blend of the two slices around nu.
  const double coordinate = (nu + 1.0) / 2.0 * (nu_size_ - 1);
  const double slice = std::floor(coordinate), lerp = coordinate - slice;
  const int i = std::clamp(static_cast<int>(slice), 0, nu_size_ - 1);
  const vec3 first = first_[i] * (1.0 - lerp) + first_[i + 1] * lerp;
  if (!single_) return first;
  const vec3 mie = second_[i] * (1.0 - lerp) + second_[i + 1] * lerp;
  return first * glsl::RayleighPhaseFunction(nu) + mie * glsl::MiePhaseFunction(params_, nu);
}

void Baker::ComputeScatteringDensity(int order) {
  const AtmosphereParameters& grid = atmosphere_grid_;
  const int mu_s_size = grid.scattering_mu_s_size, r_size = grid.scattering_r_size;
  const int nu_size = grid.scattering_nu_size, mu_size = grid.scattering_mu_size;
  const int polar = settings_.sphere_samples, azimuths = 2 * settings_.sphere_samples;
  const double d_phi = 2.0 * kPi / azimuths;
  const int groups = static_cast<int>(medium_.groups().size());
  const vec3 albedo_over_pi = medium_.atmosphere().ground_albedo / kPi;
  const glsl::sampler2D transmittance{&transmittance_};

  const SunColumns columns(grid);
  tbb::parallel_for(0, r_size * mu_s_size, [&](int slice) {
    int z = slice / mu_s_size, mu_s_index = slice % mu_s_size;
    const ScatteringTexel slice_texel = GetScatteringTexel(grid, mu_s_index, 0, z);
    const double r = slice_texel.r, mu_s = slice_texel.mu_s;
    // Local frame: zenith along z, sun in the x-z plane.
    const vec3 zenith(0.0, 0.0, 1.0);
    const vec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);

    // Polar nodes in cos(theta), a Gauss-Legendre rule on each side of the
    // horizon: the incident radiance jumps there (long grazing sky paths
    // above, the ground below), which a rule spanning it converges on slowly.
    std::vector<double> cosines, cosine_weights;
    const double horizon = -std::sqrt(std::max(0.0, 1.0 - (params_.bottom_radius / r) * (params_.bottom_radius / r)));
    AppendGaussLegendre(polar / 2, -1.0, horizon, cosines, cosine_weights);
    AppendGaussLegendre(polar - polar / 2, horizon, 1.0, cosines, cosine_weights);

    // Incoming radiance (of the previous order) from every direction.
    std::vector<vec3> directions, radiance;
    std::vector<double> solid_angles;
    directions.reserve(polar * azimuths);
    for (int l = 0; l < polar; ++l) {
      double cos_theta = cosines[l], sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
      bool intersects = glsl::RayIntersectsGround(params_, r, cos_theta);
      double ground_distance = 0.0;
      vec3 ground_transmittance(0.0);
      if (intersects) {
        ground_distance = glsl::DistanceToBottomAtmosphereBoundary(params_, r, cos_theta);
        ground_transmittance = glsl::GetTransmittance(params_, transmittance, r, cos_theta, ground_distance, true);
      }
      const IncidentAlongNu incident_ring(*this, order - 1, r, cos_theta, mu_s, intersects);
      for (int m = 0; m < azimuths; ++m) {
        double phi = (m + 0.5) * d_phi;
        vec3 omega(std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta);
        double nu = glsl::ClampCosine(glm::dot(omega, sun));
        vec3 incident = incident_ring.At(nu);
        if (intersects) {
          vec3 ground_normal = glm::normalize(zenith * r + omega * ground_distance);
          double ground_mu_s = glsl::ClampCosine(glm::dot(ground_normal, sun));
          incident += ground_transmittance * albedo_over_pi * GroundIrradiance(order - 1, ground_mu_s);
        }
        directions.push_back(omega);
        radiance.push_back(incident);
        solid_angles.push_back(cosine_weights[l] * d_phi);
      }
    }

    std::vector<double> densities(medium_.constituent_count());
    medium_.Densities(r - params_.bottom_radius, densities.data());
    std::vector<Spectrum> group_scattering(groups);
    Spectrum total_scattering(0.0);
    for (int g = 0; g < groups; ++g) {
      group_scattering[g] = medium_.GroupScattering(g, densities.data());
      total_scattering += group_scattering[g];
    }

    const PhaseWeightedRadiance incoming(directions, radiance, solid_angles);
    for (int y = 0; y < mu_size; ++y) {
      const double mu = GetScatteringTexel(grid, mu_s_index, y, z).mu;
      for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
        int x = nu_index * mu_s_size + mu_s_index;
        const double nu = ClampedNu(columns.grid_nu[x], mu, mu_s);
        // View direction with zenith cosine mu and sun cosine nu.
        double sin_mu = std::sqrt(std::max(0.0, 1.0 - mu * mu));
        double sin_mu_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
        double cos_phi = sin_mu * sin_mu_s > 0.0 ? std::clamp((nu - mu * mu_s) / (sin_mu * sin_mu_s), -1.0, 1.0) : 1.0;
        vec3 view(sin_mu * cos_phi, sin_mu * std::sqrt(std::max(0.0, 1.0 - cos_phi * cos_phi)), mu);
        vec3 density(0.0);
        for (int g = 0; g < groups; ++g) {
          if (group_scattering[g] == Spectrum(0.0)) continue;
          density += group_scattering[g] * incoming.Mean(medium_.groups()[g].phase, view);
        }
        // Stored per unit scattering coefficient, i.e. as the phase-weighted
        // mean incoming radiance, which varies slowly with altitude; the
        // multiple-scattering integral multiplies the coefficient back at
        // each sample. Interpolating J itself between r texels overestimates
        // a thin exponential haze (linear interpolation of a convex profile),
        // so that an order could carry more light than the previous one and
        // the orders of a dense fog diverged.
        vec3 per_unit_scattering(0.0);
        for (int c = 0; c < 3; ++c) per_unit_scattering[c] = total_scattering[c] > 0.0 ? density[c] / total_scattering[c] : 0.0;
        scattering_density_.Store(x, y, z, vec4(per_unit_scattering, 0.0));
      }
    }
  });
}

void Baker::ComputeIndirectIrradiance(int order) {
  const int width = irradiance_.width, height = irradiance_.height;
  const int polar = settings_.sphere_samples, azimuths = 4 * settings_.sphere_samples;
  const double d_theta = 0.5 * kPi / polar, d_phi = 2.0 * kPi / azimuths;
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      double r, mu_s;
      glsl::GetRMuSFromIrradianceTextureUv(params_, glsl::vec2((x + 0.5) / width, (y + 0.5) / height), r, mu_s);
      const vec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
      vec3 result(0.0);
      for (int l = 0; l < polar; ++l) {
        double theta = (l + 0.5) * d_theta;
        double cos_theta = std::cos(theta), sin_theta = std::sin(theta);
        const IncidentAlongNu incident_ring(*this, order, r, cos_theta, mu_s, false);
        for (int m = 0; m < azimuths; ++m) {
          double phi = (m + 0.5) * d_phi;
          vec3 omega(std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta);
          double nu = glsl::ClampCosine(glm::dot(omega, sun));
          result += incident_ring.At(nu) * (cos_theta * sin_theta * d_theta * d_phi);
        }
      }
      delta_irradiance_.Store(x, y, 0, vec4(result, 0.0));
      vec4 total = irradiance_.Fetch(x, y) + vec4(result, 0.0);
      irradiance_.Store(x, y, 0, total);
    }
  });
}

Texture Baker::GatherAlongRays(const AtmosphereParameters& grid, const Texture& density,
                               const AtmosphereParameters& density_grid) const {
  Texture result = ScatteringGridTexture(grid);
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const int density_mu_s_size = density_grid.scattering_mu_s_size, density_nu_size = density_grid.scattering_nu_size;
  const int plane_width = density.width;  // density nu * mu_s
  const SunColumns columns(grid);
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    const int z = ray_index / mu_size, y = ray_index % mu_size;
    const int n = std::max(std::min(settings_.ray_samples, 32), settings_.ray_samples / 2);
    const RaySamples ray = SampleRay(grid, y, z, n);
    // The integrand is J times the scattering coefficient times the view's
    // transmittance. Over optically thin intervals J varies slowly and is
    // taken as linear between samples, the rest as exponential, which makes
    // the integral a weighted sum of J at the samples with weights shared by
    // all the ray's texels. Over thick ones (more than one optical depth) J
    // can fall by orders of magnitude (into a fog) and the integrand is
    // taken as exponential per unit of the view's optical depth, per texel
    // (IntegrateOverOpticalDepth).
    struct ThickInterval {
      int k, c;
      double albedo_a, albedo_b;
    };
    std::vector<ThickInterval> thick_intervals;
    std::vector<Spectrum> weight(n + 1, Spectrum(0.0));
    std::vector<Spectrum> scattering(n + 1, Spectrum(0.0));
    std::vector<bool> needed(n + 1, false);  // J is looked up there
    for (int k = 0; k <= n; ++k) {
      for (const std::vector<Spectrum>& group : ray.scattering) scattering[k] += group[k];
    }
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < 3; ++c) {
        const double view_depth = ray.optical_depth[k + 1][c] - ray.optical_depth[k][c];
        const double extinction_a = ray.extinction[k][c], extinction_b = ray.extinction[k + 1][c];
        if (view_depth > 1.0 && (extinction_a > 0.0 || extinction_b > 0.0)) {
          // Albedo per unit optical depth; a vacuum end takes the other's.
          const double albedo_a =
              extinction_a > 0.0 ? scattering[k][c] / extinction_a : scattering[k + 1][c] / extinction_b;
          const double albedo_b = extinction_b > 0.0 ? scattering[k + 1][c] / extinction_b : albedo_a;
          thick_intervals.push_back({k, c, albedo_a, albedo_b});
          needed[k] = needed[k + 1] = true;
          continue;
        }
        const double factor_a = scattering[k][c], factor_b = scattering[k + 1][c];
        const double lambda = factor_a > 0.0 && factor_b > 0.0 ? std::log(factor_b / factor_a) - view_depth
                                                                : std::numeric_limits<double>::quiet_NaN();
        const std::pair<double, double> w = LinearTimesExponentialWeights(
            factor_a * std::exp(-ray.optical_depth[k][c]), factor_b * std::exp(-ray.optical_depth[k + 1][c]), lambda,
            ray.t[k + 1] - ray.t[k]);
        weight[k][c] += w.first;
        weight[k + 1][c] += w.second;
      }
    }
    // J at each sample's (r, mu) for every (nu, mu_s) texel of the density
    // grid: the texture's r and mu interpolation, done once per sample.
    std::vector<int> samples;  // those with a non-zero weight
    std::vector<float> planes;
    planes.reserve(std::size_t(n + 1) * 4 * plane_width);
    for (int k = 0; k <= n; ++k) {
      needed[k] = needed[k] || weight[k] != Spectrum(0.0);
      if (!needed[k]) continue;
      const double mu_k = glsl::CosineAtDistance(ray.r, ray.mu, ray.t[k], ray.radius[k]);
      const glsl::vec4 uvwz =
          glsl::GetScatteringTextureUvwzFromRMuMuSNu(density_grid, ray.radius[k], mu_k, 1.0, 1.0, ray.intersects_ground);
      int y0, y1, z0, z1;
      double fy, fz;
      glsl::detail::LinearTaps(uvwz.z, density.height, y0, y1, fy);
      glsl::detail::LinearTaps(uvwz.w, density.depth, z0, z1, fz);
      const float* t00 = &density.texels[density.Index(0, y0, z0)];
      const float* t10 = &density.texels[density.Index(0, y1, z0)];
      const float* t01 = &density.texels[density.Index(0, y0, z1)];
      const float* t11 = &density.texels[density.Index(0, y1, z1)];
      const float w00 = float((1 - fy) * (1 - fz)), w10 = float(fy * (1 - fz)), w01 = float((1 - fy) * fz),
                  w11 = float(fy * fz);
      const std::size_t offset = planes.size();
      planes.resize(offset + std::size_t(4) * plane_width);
      float* plane = &planes[offset];
      for (int i = 0; i < 4 * plane_width; ++i) plane[i] = w00 * t00[i] + w10 * t10[i] + w01 * t01[i] + w11 * t11[i];
      samples.push_back(k);
    }

    // Per distinct sun direction of the ray: its nu taps in the density
    // grid (nu is the same all along the ray), then per sample its mu_s
    // taps and J, vectorised over the directions.
    const SunDirections directions = RaySunDirections(columns, ray.mu);
    const int count = static_cast<int>(directions.nu.size());
    std::vector<float> mu_s(directions.mu_s.begin(), directions.mu_s.end()), nu(directions.nu.begin(), directions.nu.end());
    std::vector<int> nu_row0(count), nu_row1(count);  // offsets of the nu rows in a plane
    std::vector<float> nu_weight(count);
    for (int j = 0; j < count; ++j) {
      const double nu_coord = 0.5 * (directions.nu[j] + 1.0) * (density_nu_size - 1);
      const int nu0 = std::min(int(std::floor(nu_coord)), density_nu_size - 1), nu1 = std::min(nu0 + 1, density_nu_size - 1);
      nu_row0[j] = 4 * nu0 * density_mu_s_size, nu_row1[j] = 4 * nu1 * density_mu_s_size;
      nu_weight[j] = float(nu_coord - nu0);
    }
    const MuSCoordinate mu_s_coordinate(density_grid);
    std::vector<Spectrum> directions_sum(count);
    std::vector<float> mu_s_k(count), mu_s_weight(count), values(count);
    std::vector<int> mu_s_left(count);
    std::vector<float> sums[3], source;  // source: J per sample, channel and direction, for thick intervals
    for (auto& sum : sums) sum.assign(count, 0.0f);
    if (!thick_intervals.empty()) source.assign(std::size_t(n + 1) * 3 * count, 0.0f);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const int k = samples[i];
      const float* plane = &planes[i * std::size_t(4) * plane_width];
      const float from_mu_s = float(ray.r / ray.radius[k]), from_nu = float(ray.t[k] / ray.radius[k]);
#pragma omp simd
      for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
      mu_s_coordinate.Taps(mu_s_k.data(), count, mu_s_left.data(), mu_s_weight.data());
      for (int c = 0; c < 3; ++c) {
        const float w = float(weight[k][c]);
        float* sum = sums[c].data();
        float* value = source.empty() ? values.data() : &source[(std::size_t(k) * 3 + c) * count];
#pragma omp simd
        for (int j = 0; j < count; ++j) {
          const int a = nu_row0[j] + 4 * mu_s_left[j] + c, b = nu_row1[j] + 4 * mu_s_left[j] + c;
          const float f = mu_s_weight[j];
          const float along_a = plane[a] + f * (plane[a + 4] - plane[a]);
          const float along_b = plane[b] + f * (plane[b + 4] - plane[b]);
          value[j] = along_a + nu_weight[j] * (along_b - along_a);
          sum[j] += w * value[j];
        }
      }
    }
    for (int j = 0; j < count; ++j) {
      Spectrum sum(sums[0][j], sums[1][j], sums[2][j]);
      for (const ThickInterval& interval : thick_intervals) {
        const int k = interval.k, c = interval.c;
        const double value_a = source[(std::size_t(k) * 3 + c) * count + j] * interval.albedo_a;
        const double value_b = source[(std::size_t(k + 1) * 3 + c) * count + j] * interval.albedo_b;
        sum[c] += IntegrateOverOpticalDepth(value_a, value_b, 0.0, 0.0, ray.optical_depth[k][c],
                                            ray.optical_depth[k + 1][c]);
      }
      directions_sum[j] = sum;
    }
    for (int x = 0; x < int(directions.of_texel.size()); ++x) {
      result.Store(x, y, z, vec4(directions_sum[directions.of_texel[x]], 0.0));
    }
  });
  return result;
}

}  // namespace

ScatteringTexel GetScatteringTexel(const glsl::AtmosphereParameters& parameters, int x, int y, int z) {
  const int mu_s_size = parameters.scattering_mu_s_size;
  int nu_index = x / mu_s_size, mu_s_index = x % mu_s_size;
  vec4 uvwz(double(nu_index) / (parameters.scattering_nu_size - 1), (mu_s_index + 0.5) / mu_s_size,
            (y + 0.5) / parameters.scattering_mu_size, (z + 0.5) / parameters.scattering_r_size);
  ScatteringTexel t;
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(parameters, uvwz, t.r, t.mu, t.mu_s, t.grid_nu,
                                             t.ray_intersects_ground);
  t.nu = ClampedNu(t.grid_nu, t.mu, t.mu_s);
  return t;
}

double ClampedNu(double nu, double mu, double mu_s) {
  const double spread = std::sqrt(std::max(0.0, (1.0 - mu * mu) * (1.0 - mu_s * mu_s)));
  return std::clamp(nu, mu * mu_s - spread, mu * mu_s + spread);
}

double EstimatedBakeBytes(const BakeSettings& s) {
  constexpr double kFixedBytes = 160.0 * 1024.0 * 1024.0, kBytesPerTexel = 160.0;
  const double texels =
      double(s.scattering_r_size) * s.scattering_mu_size * s.scattering_mu_s_size * s.scattering_nu_size;
  return kFixedBytes + kBytesPerTexel * texels;
}

void BakeSettings::Validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw InputError(message);
  };
  auto size = [&](int value, int minimum, const char* name) {
    require(value >= minimum && value <= 4096,
            std::string(name) + " = " + std::to_string(value) + " must be in [" + std::to_string(minimum) + ", 4096]");
  };
  size(transmittance_width, 2, "transmittance width");
  size(transmittance_height, 2, "transmittance height");
  size(irradiance_width, 2, "irradiance width");
  size(irradiance_height, 2, "irradiance height");
  size(scattering_r_size, 2, "scattering r size");
  size(scattering_mu_size, 4, "scattering mu size");
  size(scattering_mu_s_size, 2, "scattering mu_s size");
  size(scattering_nu_size, 2, "scattering nu size");
  require(scattering_mu_size % 2 == 0,
          "scattering mu size = " + std::to_string(scattering_mu_size) + " must be even");
  require(orders >= 0 && orders <= 100, "orders = " + std::to_string(orders) + " must be in [1, 100] or 0 (auto)");
  require(max_orders >= 2 && max_orders <= 1000,
          "max orders = " + std::to_string(max_orders) + " must be in [2, 1000]");
  require(order_tolerance > 0.0 && order_tolerance < 1.0,
          "order tolerance = " + std::to_string(order_tolerance) + " must be in (0, 1)");
  require(transmittance_samples >= 8 && transmittance_samples <= 100000,
          "transmittance samples = " + std::to_string(transmittance_samples) + " must be in [8, 100000]");
  require(ray_samples >= 2 && ray_samples <= 100000,
          "ray samples = " + std::to_string(ray_samples) + " must be in [2, 100000]");
  require(higher_order_divisor >= 1 && higher_order_divisor <= 64,
          "higher-order divisor = " + std::to_string(higher_order_divisor) + " must be in [1, 64]");
  require(sphere_samples >= 2 && sphere_samples <= 1024,
          "sphere samples = " + std::to_string(sphere_samples) + " must be in [2, 1024]");
  require(threads >= 0, "threads = " + std::to_string(threads) + " must be >= 0");
  if (const std::optional<ScatteringRange>& range = scattering_range) {
    require(range->altitude_min_m >= 0.0 && range->altitude_min_m < range->altitude_max_m,
            "scattering altitude range [" + std::to_string(range->altitude_min_m) + ", " +
                std::to_string(range->altitude_max_m) + "] m must be non-empty and above the ground");
    require(range->mu_s_min >= -1.0 && range->mu_s_min < range->mu_s_max && range->mu_s_max <= 1.0,
            "scattering mu_s range [" + std::to_string(range->mu_s_min) + ", " + std::to_string(range->mu_s_max) +
                "] must be non-empty and within [-1, 1]");
    size(range->atmosphere_r_size, 2, "scattering r size over the atmosphere");
    size(range->atmosphere_mu_size, 4, "scattering mu size over the atmosphere");
    size(range->atmosphere_mu_s_size, 2, "scattering mu_s size over the atmosphere");
    require(range->atmosphere_ray_samples >= 2 && range->atmosphere_ray_samples <= 100000,
            "ray samples over the atmosphere = " + std::to_string(range->atmosphere_ray_samples) +
                " must be in [2, 100000]");
    require(range->atmosphere_mu_size % 2 == 0, "scattering mu size over the atmosphere = " +
                                                    std::to_string(range->atmosphere_mu_size) + " must be even");
  }
}

glsl::AtmosphereParameters MakeAtmosphereParameters(const Atmosphere& atmosphere, const BakeSettings& settings) {
  glsl::AtmosphereParameters p;
  p.solar_irradiance = atmosphere.solar_irradiance;
  p.sun_angular_radius = atmosphere.sun_angular_radius_rad;
  p.bottom_radius = atmosphere.bottom_radius_m;
  p.top_radius = atmosphere.top_radius_m;
  p.mu_s_min = atmosphere.mu_s_min;
  Medium medium(atmosphere);
  Spectrum mie_scattering(0.0), other_scattering(0.0);
  for (int g = 0; g < static_cast<int>(medium.groups().size()); ++g) {
    for (int c : medium.groups()[g].constituents) {
      const Constituent& constituent = atmosphere.constituents[c];
      Spectrum ground = constituent.scattering_per_m * constituent.density.At(0.0);
      (g == medium.mie_group() ? mie_scattering : other_scattering) += ground;
    }
  }
  if (medium.mie_group() >= 0) {
    const PhaseFunction& phase = medium.groups()[medium.mie_group()].phase;
    p.mie_phase = phase.kind == PhaseKind::kHenyeyGreenstein ? glsl::PHASE_HENYEY_GREENSTEIN
                                                              : glsl::PHASE_CORNETTE_SHANKS;
    p.mie_g = phase.g;
  }
  if (settings.pack_single_mie_in_alpha) {
    bool ratio_defined = mie_scattering.x > 0.0 && other_scattering.x > 0.0 && other_scattering.y > 0.0 &&
                         other_scattering.z > 0.0;
    if (!ratio_defined) {
      throw InputError(atmosphere.name +
                       ": single Mie can only be packed into alpha when both the Mie and the other scattering "
                       "constituents scatter red light at the ground");
    }
    p.mie_to_rayleigh_scattering_ratio = mie_scattering / other_scattering;
    p.single_mie_in_scattering_alpha = 1;
  }
  p.transmittance_width = settings.transmittance_width;
  p.transmittance_height = settings.transmittance_height;
  p.scattering_r_size = settings.scattering_r_size;
  p.scattering_mu_size = settings.scattering_mu_size;
  p.scattering_mu_s_size = settings.scattering_mu_s_size;
  p.scattering_nu_size = settings.scattering_nu_size;
  p.irradiance_width = settings.irradiance_width;
  p.irradiance_height = settings.irradiance_height;
  p.scattering_r_min = atmosphere.bottom_radius_m;
  p.scattering_r_max = atmosphere.top_radius_m;
  p.scattering_mu_s_min = atmosphere.mu_s_min;
  p.scattering_mu_s_max = 1.0;
  if (const std::optional<ScatteringRange>& range = settings.scattering_range) {
    p.scattering_r_min = atmosphere.bottom_radius_m + range->altitude_min_m;
    p.scattering_r_max = atmosphere.bottom_radius_m + range->altitude_max_m;
    p.scattering_mu_s_min = range->mu_s_min;
    p.scattering_mu_s_max = range->mu_s_max;
  }
  SetAltitudeProfiles(atmosphere, &p);
  return p;
}

glsl::AtmosphereParameters AtmosphereGrid(const Atmosphere& atmosphere, const BakeSettings& settings) {
  if (!settings.scattering_range) return MakeAtmosphereParameters(atmosphere, settings);
  BakeSettings whole = settings;
  whole.scattering_range.reset();
  whole.scattering_r_size = settings.scattering_range->atmosphere_r_size;
  whole.scattering_mu_size = settings.scattering_range->atmosphere_mu_size;
  whole.scattering_mu_s_size = settings.scattering_range->atmosphere_mu_s_size;
  return MakeAtmosphereParameters(atmosphere, whole);
}

void SetAltitudeProfiles(const Atmosphere& atmosphere, glsl::AtmosphereParameters* parameters) {
  const Medium medium(atmosphere);
  std::vector<double> densities(medium.constituent_count());
  const double height = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
    // The sample altitudes of definitions.glsl.
    double x = double(i) / double(glsl::ALTITUDE_PROFILE_SIZE - 1);
    medium.Densities(height * x * x, densities.data());
    Spectrum mie(0.0), others(0.0);
    for (int g = 0; g < static_cast<int>(medium.groups().size()); ++g) {
      (g == medium.mie_group() ? mie : others) += medium.GroupScattering(g, densities.data());
    }
    parameters->extinction_profile[i] = medium.Extinction(densities.data());
    parameters->mie_scattering_profile[i] = mie;
    parameters->rayleigh_scattering_profile[i] = others;
  }
}

LutSet Bake(const Atmosphere& atmosphere, const BakeSettings& settings, BakeReport* report,
            const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot) {
  settings.Validate();
  std::unique_ptr<tbb::global_control> thread_limit;
  if (settings.threads > 0) {
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                         static_cast<size_t>(settings.threads));
  }
  Baker baker(atmosphere, settings);
  return baker.Run(report, progress, order_snapshot);
}

}  // namespace skybake

#include "shaders_runtime/twin.h"

namespace skybake {
TwinTables MakeTwinTables(const LutSet& luts) {
  return TwinTables{luts.parameters, &luts.transmittance, &luts.scattering, &luts.single_mie_scattering,
                    &luts.irradiance};
}
}  // namespace skybake
