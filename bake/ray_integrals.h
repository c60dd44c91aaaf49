// Integrals along the bake's rays: the quadrature rules for one interval
// between two samples (exponential trapezoid, linear times exponential, the
// rule over optical depth for thick intervals), the sample distances and the
// samples of one ray of the scattering table.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "bake/detail.h"
#include "core/constants.h"
#include "core/spectrum.h"

namespace skybake::detail {

// Integral over an interval of width h of a positive function that takes the
// values a and b at its ends, assuming it is exponential in between; the
// ordinary trapezoid where that assumption cannot hold (a zero end).
inline double ExponentialTrapezoid(double a, double b, double h) {
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
inline std::pair<double, double> LinearTimesExponentialWeights(double g_a, double g_b, double lambda, double h) {
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
inline double IntegrateOverOpticalDepth(double value_a, double value_b, double sun_a, double sun_b, double tau_a,
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
inline Spectrum IntegrateInterval(const RayIntegrand& a, const RayIntegrand& b, double h) {
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
inline std::vector<double> RayDistances(double d, int n) {
  std::vector<double> t(n + 1);
  for (int k = 0; k <= n; ++k) t[k] = d * k / n;
  return t;
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
}  // namespace skybake::detail
