// The candidate surfaces for the relative optical path m(μ, h), written once
// as templates so that Ceres differentiates exactly the expression that the
// report, the mesh and the generated GLSL / C++ evaluate.
//
// Every form has three shape parameters p_k(h), each interpolated
// quadratically in the normalised altitude t = (h - h_lo) / (h_hi - h_lo)
// through its values at t = 0, 1/2, 1 (Lagrange nodes: a bounded node value
// bounds the curve, which keeps exp(p) inside float range in the shader),
// plus one "layer top" coefficient τ = 1 + exp(c9) > 1: the parameter that
// sets the horizon value is scaled by a power of (τ - t). Where a layer ends
// just above the range (a fog slab of thickness T seen from h → T) the
// horizon value grows like (T - h)^-1/2, which no polynomial in t follows;
// for profiles without such a top τ runs off and the factor is smooth.
// Ten coefficients per constituent.
//
// kChapmanChord: m = D(1) / D(μ),  D(μ) = μ + a·ε / (sqrt(μ² + ε) + b·μ)
//   with ε = exp(p0)·(τ - t), a = exp(p1), b = exp(p2).
//   Exact for a constant-density shell above the observer (a = 1/2, b = 1:
//   the chord of a spherical slab, ε = (2rT + T²)/r²) and for a thin elevated
//   layer (a = 1, b = 1: m = 1/sqrt(μ² + ε)); for an exponential profile it
//   is a rational approximation of the Chapman function
//   sqrt(πx/2)·erfcx(μ·sqrt(x/2)), x = r/H, whose horizon value
//   D(1)/D(0) ≈ 1/(a·sqrt ε) carries the sqrt(πR/2H) scaling.
// kKasten: m = 1 / (μ + a·(b - θ°)^-c), a = exp(p0)·sqrt(τ - t),
//   b = 90 + exp(p1), c = exp(p2): Kasten's and Iqbal's air-mass form (Iqbal: a = 0.15,
//   b = 93.885, c = 1.253) with altitude-dependent coefficients.
#pragma once

#include <array>
#include <cmath>
#include <string>

namespace skybake::fit {

enum class FormKind { kChapmanChord, kKasten };
constexpr int kShapeParameters = 3;
// [parameter * 3 + node] for the shape parameters, then ln(τ - 1).
constexpr int kLayerTopCoefficient = 3 * kShapeParameters;
constexpr int kCoefficientCount = kLayerTopCoefficient + 1;

const char* ToString(FormKind kind);
// False for an unknown name.
bool ParseFormKind(const std::string& name, FormKind* kind);
// Names of the shape parameters p0..p2 as stored in fit.json.
// The layer-top coefficient is "ln_tau_minus_1" in both forms.
std::array<const char*, kShapeParameters> ParameterNames(FormKind kind);

// Bounds on every node value, so exp(p) and products of two of them stay
// far inside float range (the shader evaluates in float).
struct ParameterBounds {
  double lower, upper;
};
// `parameter` in [0, kShapeParameters) bounds every node value of that
// parameter; kShapeParameters bounds the layer-top coefficient.
ParameterBounds Bounds(FormKind kind, int parameter);

// Lagrange weights of the nodes t = 0, 1/2, 1.
template <typename T>
std::array<T, 3> NodeWeights(T t) {
  return {(T(1) - t) * (T(1) - T(2) * t), T(4) * t * (T(1) - t), t * (T(2) * t - T(1))};
}

// m for coefficients c (see kCoefficientCount). `mu` in [0, 1], `t` in [0, 1].
// Works for double and for ceres::Jet (only the coefficients are Jets).
template <typename T>
T EvaluateForm(FormKind kind, const T* c, double mu, double t) {
  using std::exp;
  using std::pow;
  using std::sqrt;
  std::array<double, 3> w = NodeWeights(t);
  T p[kShapeParameters];
  for (int k = 0; k < kShapeParameters; ++k)
    p[k] = w[0] * c[3 * k] + w[1] * c[3 * k + 1] + w[2] * c[3 * k + 2];
  T to_top = T(1.0 - t) + exp(c[kLayerTopCoefficient]);  // τ - t, without rounding τ first
  if (kind == FormKind::kChapmanChord) {
    T eps = exp(p[0]) * to_top, a = exp(p[1]), b = exp(p[2]);
    // a·ε/(sqrt(μ²+ε) + b·μ) rather than a difference of square roots: no
    // cancellation at the zenith, where ε ≪ 1.
    T d_zenith = T(1.0) + a * eps / (sqrt(T(1.0) + eps) + b);
    T d = T(mu) + a * eps / (sqrt(T(mu * mu) + eps) + b * T(mu));
    return d_zenith / d;
  }
  constexpr double kDegreesPerRadian = 57.295779513082320876798;
  double theta_deg = std::acos(mu) * kDegreesPerRadian;
  T a = exp(p[0]) * sqrt(to_top), b = T(90.0) + exp(p[1]), c_exp = exp(p[2]);
  return T(1.0) / (T(mu) + a * pow(b - T(theta_deg), -c_exp));
}

// Iqbal's relative optical path 1 / (cos θ + 0.15·(93.885 - θ°)^-1.253),
// altitude-independent, the baseline every fit is compared with.
double IqbalRelativeOpticalPath(double mu);

}  // namespace skybake::fit
