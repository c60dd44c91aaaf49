// The CPU bake. The structure follows Bruneton's precomputation (transmittance,
// single scattering, then per order: scattering density, indirect irradiance,
// multiple scattering), with three CPU-specific choices:
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

#include "bake/errors.h"
#include "bake/medium.h"
#include "shaders_runtime/runtime.h"

namespace skybake {

namespace {

using glsl::AtmosphereParameters;
using glsl::Texture;
using glsl::vec3;
using glsl::vec4;
constexpr double kPi = 3.14159265358979323846;
// Intervals of a ray that the planet's shadow edge crosses are integrated on
// this many sub-intervals (twilight rays; measured against brute force).
constexpr int kShadowEdgeSubdivisions = 16;

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
    // Per unit of the view's optical depth.
    const double width = view_depth;
    const double value_a = extinction_a > 0.0 ? a.source[c] / extinction_a : b.source[c] / extinction_b;
    const double value_b = extinction_b > 0.0 ? b.source[c] / extinction_b : value_a;
    if (value_a <= 0.0 || value_b <= 0.0) {
      // An end is truly dark (in the planet's shadow, or nothing scatters):
      // linear between the ends, integrated exactly against exp(-tau).
      // With u the view's optical depth from a and g the values without the
      // view's attenuation: integral over [0, x] of (ga + (gb - ga) u / x) exp(-u).
      double ga = value_a * std::exp(-a.sun_optical_depth[c]), gb = value_b * std::exp(-b.sun_optical_depth[c]);
      double x = width, decay = -std::expm1(-x), ramp = (decay - x * std::exp(-x)) / x;
      result[c] = std::exp(-a.view_optical_depth[c]) * (ga * decay + (gb - ga) * ramp);
      continue;
    }
    double log_a = std::log(value_a) - (a.view_optical_depth[c] + a.sun_optical_depth[c]);
    double log_b = std::log(value_b) - (b.view_optical_depth[c] + b.sun_optical_depth[c]);
    double fa = std::exp(log_a), fb = std::exp(log_b), log_ratio = log_b - log_a;
    result[c] = std::abs(log_ratio) < 1e-4 ? 0.5 * width * (fa + fb) : width * (fb - fa) / log_ratio;
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

// The grid of each higher order's radiance: the scattering table's r and mu
// sizes divided by `divisor` (mu kept even). mu_s and nu are kept: halving
// mu_s as well raised the sky irradiance error of the report's case set
// from 12.6% to 15.4% RMS and tripled its twilight error, as the light of
// low suns changes fastest with mu_s.
AtmosphereParameters HigherOrderGrid(AtmosphereParameters grid, int divisor) {
  grid.scattering_r_size = std::max(2, grid.scattering_r_size / divisor);
  grid.scattering_mu_size = std::max(4, grid.scattering_mu_size / divisor / 2 * 2);
  return grid;
}

// target += source * factor, per channel, over the rgb of every texel.
void AddScaled(const Texture& source, const Spectrum& factor, Texture& target) {
  for (std::size_t i = 0; i < target.texels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) target.texels[i + c] += float(source.texels[i + c] * factor[c]);
  }
}

Texture ScatteringGridTexture(const AtmosphereParameters& grid) {
  return Texture(grid.scattering_nu_size * grid.scattering_mu_s_size, grid.scattering_mu_size, grid.scattering_r_size);
}

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
        orders_grid_(HigherOrderGrid(params_, settings.higher_order_divisor)) {}

  LutSet Run(BakeReport* report, const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot);

 private:
  template <typename F>
  void Phase(const std::string& name, F&& work);

  void ComputeTransmittance();
  void ComputeSingleScattering();
  void ComputeScatteringDensity(int order);
  void ComputeIndirectIrradiance(int order);
  // The light of the orders whose scattering density (per unit scattering
  // coefficient, on the grid of `density_grid`) is `density`, arriving at
  // every texel of a table on the grid `grid`: the density integrated along
  // each texel's ray.
  Texture GatherAlongRays(const AtmosphereParameters& grid, const Texture& density,
                          const AtmosphereParameters& density_grid) const;
  // Whether the orders are gathered on a coarser grid than the table's, so
  // that the table's higher orders come from one gather of their summed
  // densities at the end.
  bool GatherAtEnd() const { return settings_.higher_order_divisor > 1; }
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

  // Radiance of scattering order `order` arriving at radius r from direction
  // (mu, nu) with the sun at mu_s, excluding light reflected by the ground.
  vec3 IncidentRadiance(int order, double r, double mu, double mu_s, double nu, bool intersects_ground) const;
  // Irradiance of order `order` on the ground where the sun is at mu_s.
  vec3 GroundIrradiance(int order, double mu_s) const;
  vec3 DirectIrradiance(double r, double mu_s) const;

  Medium medium_;
  BakeSettings settings_;
  AtmosphereParameters params_;
  // The grid of each order's radiance (BakeSettings::higher_order_divisor).
  AtmosphereParameters orders_grid_;
  BakeReport report_;
  BakeProgress progress_;

  Texture transmittance_;
  Texture irradiance_;
  Texture single_mie_;            // single scattering of the Mie group, phase free
  Texture single_rayleigh_;       // single scattering of the other groups / Rayleigh phase
  Texture delta_multiple_;        // radiance of the latest order >= 2, on orders_grid_
  Texture scattering_density_;    // J of the current order per unit scattering coefficient
  // Sum over the orders >= 2 so far, and their tail, of their radiance, or
  // of their J where GatherAtEnd(); on the table's grid.
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
      LutSet tables = AssembleTables(transmittance_, irradiance_, ScatteringTable(), single_mie_);
      tables.settings.orders = order;  // exactly these orders, no tail
      tables.settings.extrapolate_tail = false;
      order_snapshot(order, tables, PhaseSecondsSoFar());
    }
  };
  auto start = std::chrono::steady_clock::now();
  const BakeSettings& s = settings_;
  transmittance_ = Texture(s.transmittance_width, s.transmittance_height);
  irradiance_ = Texture(s.irradiance_width, s.irradiance_height);
  single_mie_ = ScatteringGridTexture(params_);
  single_rayleigh_ = ScatteringGridTexture(params_);

  Phase("transmittance", [&] { ComputeTransmittance(); });
  Phase("single scattering", [&] { ComputeSingleScattering(); });
  if (s.orders != 1) {  // 0 = auto
    scattering_density_ = ScatteringGridTexture(params_);
    higher_orders_ = ScatteringGridTexture(params_);
    delta_irradiance_ = Texture(s.irradiance_width, s.irradiance_height);
  }
  report_.orders_used = 1;
  snapshot(1);
  report_.remaining_error = -1.0;  // unknown until two orders can be compared
  const bool auto_orders = s.orders == 0;
  OrderConvergence convergence;
  // Convergence is measured on means over the tables (each order's on its own grid).
  OrderSums sums;
  sums.table = TableMean(single_rayleigh_, params_, {});
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
      delta_multiple_ = GatherAlongRays(orders_grid_, scattering_density_, params_);
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
                                 std::move(single_mie_));
  report_.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = report_;
  return result;
}

Texture Baker::ScatteringTable() const {
  Texture table = single_rayleigh_;
  if (report_.orders_used < 2) return table;
  const Texture higher = GatherAtEnd() ? GatherAlongRays(params_, higher_orders_, params_) : higher_orders_;
  const int mu_s_size = params_.scattering_mu_s_size;
  const std::vector<double> packing = PackingFactors(params_);
  for (std::size_t i = 0; i < table.texels.size(); i += 4) {
    const int x = int((i / 4) % table.width);
    const double factor = packing[x / mu_s_size];
    for (int c = 0; c < 3; ++c) table.texels[i + c] += float(higher.texels[i + c] * factor);
  }
  return table;
}

std::vector<double> Baker::PackingFactors(const AtmosphereParameters& grid) {
  std::vector<double> factors(grid.scattering_nu_size);
  for (int nu = 0; nu < grid.scattering_nu_size; ++nu) factors[nu] = MultipleScatteringPackingFactor(grid, nu);
  return factors;
}

Spectrum Baker::TableMean(const Texture& table, const AtmosphereParameters& grid, const std::vector<double>& per_nu) {
  const int mu_s_size = grid.scattering_mu_s_size;
  Spectrum sum(0.0);
  for (std::size_t i = 0; i < table.texels.size(); i += 4) {
    const int x = int((i / 4) % table.width);
    const double factor = per_nu.empty() ? 1.0 : per_nu[x / mu_s_size];
    for (int c = 0; c < 3; ++c) sum[c] += table.texels[i + c] * factor;
  }
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

void Baker::ComputeSingleScattering() {
  const int mu_size = params_.scattering_mu_size, r_size = params_.scattering_r_size;
  const int mu_s_size = params_.scattering_mu_s_size, nu_size = params_.scattering_nu_size;
  const int groups = static_cast<int>(medium_.groups().size());
  const int mie = medium_.mie_group();
  const glsl::sampler2D transmittance{&transmittance_};
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    int z = ray_index / mu_size, y = ray_index % mu_size;
    const int n = settings_.ray_samples;
    const RaySamples ray = SampleRay(params_, y, z, n);
    // Per group and sample, the factors shared by all the ray's texels: the
    // scattering coefficient times the view's transmittance, and the log of
    // its ratio between neighbouring samples (so that the exponential
    // trapezoid below needs no logarithm per texel).
    std::vector<std::vector<Spectrum>> base(groups, std::vector<Spectrum>(n + 1));
    std::vector<std::vector<Spectrum>> log_ratio(groups, std::vector<Spectrum>(n, Spectrum(0.0)));
    std::vector<Spectrum> view_transmittance(n + 1);
    std::vector<bool> thin(n);  // interval less than one optical depth thick for the view
    for (int k = 0; k <= n; ++k) {
      view_transmittance[k] = glm::exp(-ray.optical_depth[k]);
      for (int g = 0; g < groups; ++g) base[g][k] = ray.scattering[g][k] * view_transmittance[k];
    }
    for (int k = 0; k < n; ++k) {
      Spectrum view_depth = ray.optical_depth[k + 1] - ray.optical_depth[k];
      thin[k] = std::max({view_depth.x, view_depth.y, view_depth.z}) <= 1.0;
      for (int g = 0; g < groups; ++g) {
        for (int c = 0; c < 3; ++c) {
          double a = base[g][k][c], b = base[g][k + 1][c];
          log_ratio[g][k][c] = a > 0.0 && b > 0.0 ? std::log(b / a) : 0.0;
        }
      }
    }

    std::vector<double> phase_ratio(groups), densities(medium_.constituent_count());
    std::vector<Spectrum> tau_sun(n + 1), sun_transmittance(n + 1), scattering_k(groups);
    std::vector<double> visible(n + 1);
    for (int mu_s_index = 0; mu_s_index < mu_s_size; ++mu_s_index) {
      double previous_nu = std::numeric_limits<double>::quiet_NaN();
      Spectrum rayleigh_sum(0.0), mie_sum(0.0);
      for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
        const int x = nu_index * mu_s_size + mu_s_index;
        const ScatteringTexel texel = GetScatteringTexel(params_, x, y, z);
        const double r = texel.r, mu_s = texel.mu_s, nu = texel.nu;
        // Slices clamped to the same nu have the same integral.
        if (nu != previous_nu) {
          previous_nu = nu;
          // The table divides out the Rayleigh phase; other phases are applied here.
          for (int g = 0; g < groups; ++g) {
            phase_ratio[g] = medium_.groups()[g].phase.Evaluate(nu) / glsl::RayleighPhaseFunction(nu);
          }
          for (int k = 0; k <= n; ++k) {
            double mu_s_k = glsl::ClampCosine((r * mu_s + ray.t[k] * nu) / ray.radius[k]);
            visible[k] = glsl::SunVisibleFraction(params_, ray.radius[k], mu_s_k);
            tau_sun[k] = visible[k] > 0.0 ? glsl::GetOpticalDepthToTopAtmosphereBoundary(params_, transmittance,
                                                                                        ray.radius[k], mu_s_k)
                                          : Spectrum(0.0);
            sun_transmittance[k] = visible[k] > 0.0 ? glm::exp(-tau_sun[k]) : Spectrum(0.0);
          }
          // Scattered light at distance t along the ray, per group kind (the
          // general form, for the intervals the fast path below does not take).
          auto sample = [&](double t, double r_t, const Spectrum& optical_depth, const Spectrum& extinction,
                            const Spectrum* scattering, RayIntegrand& rayleigh_out, RayIntegrand& mie_out,
                            double& visible_out) {
            double mu_s_t = glsl::ClampCosine((r * mu_s + t * nu) / r_t);
            visible_out = glsl::SunVisibleFraction(params_, r_t, mu_s_t);
            Spectrum tau = glsl::GetOpticalDepthToTopAtmosphereBoundary(params_, transmittance, r_t, mu_s_t);
            Spectrum other(0.0);
            for (int g = 0; g < groups; ++g) {
              if (g != mie) other += scattering[g] * phase_ratio[g];
            }
            Spectrum attenuation = glm::exp(-(optical_depth + tau));
            Spectrum rayleigh_source = other * visible_out,
                     mie_source = mie >= 0 ? scattering[mie] * visible_out : Spectrum(0.0);
            rayleigh_out = RayIntegrand{rayleigh_source, optical_depth, tau, extinction, rayleigh_source * attenuation};
            mie_out = RayIntegrand{mie_source, optical_depth, tau, extinction, mie_source * attenuation};
          };
          auto sample_at = [&](int k, RayIntegrand& rayleigh_out, RayIntegrand& mie_out) {
            for (int g = 0; g < groups; ++g) scattering_k[g] = ray.scattering[g][k];
            double unused;
            sample(ray.t[k], ray.radius[k], ray.optical_depth[k], ray.extinction[k], scattering_k.data(), rayleigh_out,
                   mie_out, unused);
          };
          rayleigh_sum = Spectrum(0.0), mie_sum = Spectrum(0.0);
          for (int k = 0; k < n; ++k) {
            const double h = ray.t[k + 1] - ray.t[k];
            if (visible[k] == 0.0 && visible[k + 1] == 0.0) continue;
            if (thin[k] && visible[k] == 1.0 && visible[k + 1] == 1.0) {
              // Fully lit, optically thin: the exponential trapezoid of each
              // group's integrand, its log ratio from the shared part's and
              // the sun's optical depths.
              const Spectrum& sun_a = sun_transmittance[k];
              const Spectrum& sun_b = sun_transmittance[k + 1];
              for (int g = 0; g < groups; ++g) {
                Spectrum integral;
                for (int c = 0; c < 3; ++c) {
                  const double fa = base[g][k][c] * sun_a[c], fb = base[g][k + 1][c] * sun_b[c];
                  const double lambda = log_ratio[g][k][c] - (tau_sun[k + 1][c] - tau_sun[k][c]);
                  integral[c] = fa > 0.0 && fb > 0.0 && std::abs(lambda) >= 1e-4 ? h * (fb - fa) / lambda
                                                                                  : 0.5 * h * (fa + fb);
                }
                if (g == mie) {
                  mie_sum += integral;
                } else {
                  rayleigh_sum += integral * phase_ratio[g];
                }
              }
              continue;
            }
            RayIntegrand rayleigh_a, mie_a, rayleigh_b, mie_b;
            sample_at(k, rayleigh_a, mie_a);
            sample_at(k + 1, rayleigh_b, mie_b);
            if (visible[k] == visible[k + 1]) {
              rayleigh_sum += IntegrateInterval(rayleigh_a, rayleigh_b, h);
              mie_sum += IntegrateInterval(mie_a, mie_b, h);
              continue;
            }
            // The planet's shadow edge crosses this interval: the integrand
            // switches on or off within it, so subdivide it.
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
                for (int g = 0; g < groups; ++g) scattering_k[g] = medium_.GroupScattering(g, densities.data());
                Spectrum optical_depth = glm::mix(ray.optical_depth[k], ray.optical_depth[k + 1], f);
                double unused;
                sample(t, r_t, optical_depth, medium_.Extinction(densities.data()), scattering_k.data(),
                       next_rayleigh, next_mie, unused);
              }
              rayleigh_sum += IntegrateInterval(previous_rayleigh, next_rayleigh, piece);
              mie_sum += IntegrateInterval(previous_mie, next_mie, piece);
              previous_rayleigh = next_rayleigh, previous_mie = next_mie;
            }
          }
        }
        single_rayleigh_.Store(x, y, z, vec4(rayleigh_sum * params_.solar_irradiance, 0.0));
        single_mie_.Store(x, y, z, vec4(mie_sum * params_.solar_irradiance, 0.0));
      }
    }
  });
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

vec3 Baker::IncidentRadiance(int order, double r, double mu, double mu_s, double nu, bool intersects_ground) const {
  if (order == 1) {
    vec3 rayleigh(glsl::GetScattering(params_, glsl::sampler3D{&single_rayleigh_}, r, mu, mu_s, nu, intersects_ground));
    vec3 mie(glsl::GetScattering(params_, glsl::sampler3D{&single_mie_}, r, mu, mu_s, nu, intersects_ground));
    return rayleigh * glsl::RayleighPhaseFunction(nu) + mie * glsl::MiePhaseFunction(params_, nu);
  }
  return vec3(glsl::GetScattering(orders_grid_, glsl::sampler3D{&delta_multiple_}, r, mu, mu_s, nu, intersects_ground));
}

void Baker::ComputeScatteringDensity(int order) {
  const AtmosphereParameters& grid = params_;
  const int mu_s_size = grid.scattering_mu_s_size, r_size = grid.scattering_r_size;
  const int nu_size = grid.scattering_nu_size, mu_size = grid.scattering_mu_size;
  const int polar = settings_.sphere_samples, azimuths = 2 * settings_.sphere_samples;
  const double d_phi = 2.0 * kPi / azimuths;
  const int groups = static_cast<int>(medium_.groups().size());
  const vec3 albedo_over_pi = medium_.atmosphere().ground_albedo / kPi;
  const glsl::sampler2D transmittance{&transmittance_};

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
      for (int m = 0; m < azimuths; ++m) {
        double phi = (m + 0.5) * d_phi;
        vec3 omega(std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta);
        double nu = glsl::ClampCosine(glm::dot(omega, sun));
        vec3 incident = IncidentRadiance(order - 1, r, cos_theta, mu_s, nu, intersects);
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
      for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
        int x = nu_index * mu_s_size + mu_s_index;
        const ScatteringTexel texel = GetScatteringTexel(grid, x, y, z);
        const double mu = texel.mu, nu = texel.nu;
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
        for (int m = 0; m < azimuths; ++m) {
          double phi = (m + 0.5) * d_phi;
          vec3 omega(std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta);
          double nu = glsl::ClampCosine(glm::dot(omega, sun));
          result += IncidentRadiance(order, r, cos_theta, mu_s, nu, false) * (cos_theta * sin_theta * d_theta * d_phi);
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
  const int mu_s_size = grid.scattering_mu_s_size, nu_size = grid.scattering_nu_size;
  const int density_mu_s_size = density_grid.scattering_mu_s_size, density_nu_size = density_grid.scattering_nu_size;
  const int plane_width = density.width;  // density nu * mu_s
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
    // taken as exponential per unit of the view's optical depth, per texel,
    // as IntegrateInterval does.
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
    std::vector<Spectrum> source(n + 1, Spectrum(0.0));  // J at the samples, per texel
    for (int mu_s_index = 0; mu_s_index < mu_s_size; ++mu_s_index) {
      double previous_nu = std::numeric_limits<double>::quiet_NaN();
      Spectrum sum(0.0);
      for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
        const int x = nu_index * mu_s_size + mu_s_index;
        const ScatteringTexel texel = GetScatteringTexel(grid, x, y, z);
        // Slices clamped to the same nu (the edges of the range that mu and
        // mu_s allow) have the same integral.
        if (texel.nu != previous_nu) {
          previous_nu = texel.nu;
          const double nu_coord = 0.5 * (texel.nu + 1.0) * (density_nu_size - 1);
          const int nu0 = std::min(int(std::floor(nu_coord)), density_nu_size - 1), nu1 = std::min(nu0 + 1, density_nu_size - 1);
          const double f_nu = nu_coord - nu0;
          sum = Spectrum(0.0);
          for (std::size_t i = 0; i < samples.size(); ++i) {
            Spectrum& j = source[samples[i]];
            const int k = samples[i];
            const double mu_s_k = glsl::ClampCosine((ray.r * texel.mu_s + ray.t[k] * texel.nu) / ray.radius[k]);
            int m0, m1;
            double f_mu_s;
            glsl::detail::LinearTaps(glsl::GetScatteringTextureUMuS(density_grid, mu_s_k), density_mu_s_size, m0, m1, f_mu_s);
            const float* plane = &planes[i * std::size_t(4) * plane_width];
            const float* a0 = plane + 4 * (nu0 * density_mu_s_size + m0);
            const float* a1 = plane + 4 * (nu0 * density_mu_s_size + m1);
            const float* b0 = plane + 4 * (nu1 * density_mu_s_size + m0);
            const float* b1 = plane + 4 * (nu1 * density_mu_s_size + m1);
            const double w_a0 = (1 - f_nu) * (1 - f_mu_s), w_a1 = (1 - f_nu) * f_mu_s, w_b0 = f_nu * (1 - f_mu_s),
                         w_b1 = f_nu * f_mu_s;
            for (int c = 0; c < 3; ++c) j[c] = w_a0 * a0[c] + w_a1 * a1[c] + w_b0 * b0[c] + w_b1 * b1[c];
            sum += weight[k] * j;
          }
          for (const ThickInterval& interval : thick_intervals) {
            const int k = interval.k, c = interval.c;
            const double tau_a = ray.optical_depth[k][c], width = ray.optical_depth[k + 1][c] - tau_a;
            const double value_a = source[k][c] * interval.albedo_a, value_b = source[k + 1][c] * interval.albedo_b;
            if (value_a <= 0.0 || value_b <= 0.0) {
              // A dark end: linear between the ends, exactly against exp(-tau).
              const double decay = -std::expm1(-width), ramp = (decay - width * std::exp(-width)) / width;
              sum[c] += std::exp(-tau_a) * (value_a * decay + (value_b - value_a) * ramp);
              continue;
            }
            const double log_a = std::log(value_a) - tau_a, log_b = std::log(value_b) - (tau_a + width);
            const double fa = std::exp(log_a), fb = std::exp(log_b), log_ratio = log_b - log_a;
            sum[c] += std::abs(log_ratio) < 1e-4 ? 0.5 * width * (fa + fb) : width * (fb - fa) / log_ratio;
          }
        }
        result.Store(x, y, z, vec4(sum, 0.0));
      }
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
  double spread = std::sqrt(std::max(0.0, (1.0 - t.mu * t.mu) * (1.0 - t.mu_s * t.mu_s)));
  t.nu = std::clamp(t.grid_nu, t.mu * t.mu_s - spread, t.mu * t.mu_s + spread);
  return t;
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
  SetAltitudeProfiles(atmosphere, &p);
  return p;
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
