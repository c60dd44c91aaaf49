// Adaptive Gauss-Kronrod quadrature (7-point Gauss / 15-point Kronrod pairs,
// globally adaptive as in QUADPACK's QAG) for the column integrals of the fit.
//
// Density profiles have kinks and jumps at layer boundaries and clamp points;
// a Gauss rule converges slowly across them, so callers pass them as forced
// subdivision points and every panel the integrator sees is smooth.
#pragma once

#include <functional>
#include <vector>

namespace skybake::fit {

struct QuadratureOptions {
  // Stop when the summed |K15 - G7| estimate is below
  // max(absolute_tolerance, relative_tolerance * |integral|). The estimate
  // bounds the error of the 7-point rule; the 15-point result returned is far
  // more accurate for smooth panels, so 1e-9 here gives errors well below 1e-8.
  double relative_tolerance = 1e-9;
  double absolute_tolerance = 0.0;
  int max_panels = 4000;
};

struct QuadratureResult {
  double value = 0.0;
  double error_estimate = 0.0;
  int panels = 0;
  int evaluations = 0;
  bool converged = true;  // false: max_panels reached or panels too narrow to split
};

// Integrates f over [a, b] (a <= b). `breakpoints` outside (a, b) are ignored;
// duplicates are harmless.
QuadratureResult Integrate(const std::function<double(double)>& f, double a, double b,
                           const std::vector<double>& breakpoints = {},
                           const QuadratureOptions& options = {});

}  // namespace skybake::fit
