// Adaptive Simpson quadrature for the tests' brute-force references. It
// shares nothing with the bake's integrators (Gauss-Legendre, exponential
// trapezoid), so agreement between the two is evidence, not tautology.
#pragma once

#include <cmath>
#include <algorithm>
#include <functional>

#include "bake/atmosphere.h"

namespace skybake::testing {

inline double MaxAbs(double x) { return std::abs(x); }
inline double MaxAbs(const Spectrum& x) { return std::max({std::abs(x.x), std::abs(x.y), std::abs(x.z)}); }

template <typename T, typename F>
T AdaptiveSimpson(const F& f, double a, double b, T fa, T fm, T fb, T whole, double tolerance, int depth) {
  double m = 0.5 * (a + b);
  double lm = 0.5 * (a + m), rm = 0.5 * (m + b);
  T flm = f(lm), frm = f(rm);
  T left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
  T right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
  T delta = left + right - whole;
  double error = MaxAbs(delta);
  if (depth <= 0 || error <= 15.0 * tolerance) return left + right + delta / 15.0;
  return AdaptiveSimpson(f, a, m, fa, flm, fm, left, 0.5 * tolerance, depth - 1) +
         AdaptiveSimpson(f, m, b, fm, frm, fb, right, 0.5 * tolerance, depth - 1);
}

// Integral of f over [a, b] to an absolute tolerance, on `pieces` equal
// sub-intervals first (so narrow features are not stepped over).
template <typename T, typename F>
T Integrate(const F& f, double a, double b, double tolerance, int pieces = 16) {
  T sum = 0.0 * f(a);
  double h = (b - a) / pieces;
  for (int i = 0; i < pieces; ++i) {
    double x0 = a + i * h, x1 = x0 + h, xm = 0.5 * (x0 + x1);
    T f0 = f(x0), fm = f(xm), f1 = f(x1);
    T whole = h / 6.0 * (f0 + 4.0 * fm + f1);
    sum += AdaptiveSimpson(f, x0, x1, f0, fm, f1, whole, tolerance / pieces, 40);
  }
  return sum;
}

// Extinction optical depth along the ray from radius r, direction cosine mu,
// over distance d, to a relative tolerance.
inline Spectrum ExactOpticalDepth(const Atmosphere& atmosphere, double r, double mu, double d,
                                  double relative_tolerance = 1e-9) {
  if (d <= 0.0) return Spectrum(0.0);
  auto extinction = [&](double t) {
    double radius = std::sqrt(t * t + 2.0 * r * mu * t + r * r);
    return atmosphere.ExtinctionAt(radius - atmosphere.bottom_radius_m);
  };
  // Scale the absolute tolerance by a rough magnitude of the result.
  Spectrum rough = Integrate<Spectrum>(extinction, 0.0, d, 1e-3 * d * 1e-6, 64);
  double scale = std::max({rough.x, rough.y, rough.z, 1e-30});
  return Integrate<Spectrum>(extinction, 0.0, d, relative_tolerance * scale, 64);
}

}  // namespace skybake::testing
