// Gauss-Kronrod quadrature (the 7-point Gauss rule embedded in the 15-point
// Kronrod rule, QUADPACK's qk15) for the deterministic integrals of the
// reference solver: optical depths, and the transmittances made from them.
#pragma once

#include "core/quadrature.h"
#include "core/spectrum.h"

namespace skybake::reference {

// The 15-point Kronrod estimate of the integral of f over [a, b] and the
// 7-point Gauss estimate from the same nodes; |kronrod - gauss| bounds the
// error of the Gauss rule and so, very pessimistically, of the Kronrod one.
struct GaussKronrodResult {
  Spectrum kronrod{0.0};
  Spectrum gauss{0.0};
};

// f: Spectrum(double t).
template <typename F>
GaussKronrodResult GaussKronrod15(F&& f, double a, double b);

template <typename F>
GaussKronrodResult GaussKronrod15(F&& f, double a, double b) {
  const double centre = 0.5 * (a + b), half = 0.5 * (b - a);
  Spectrum f_centre = f(centre);
  Spectrum kronrod = f_centre * GaussKronrod15Rule::kKronrodWeights[7];
  Spectrum gauss = f_centre * GaussKronrod15Rule::kGaussWeights[3];
  for (int i = 0; i < 7; ++i) {
    double dx = half * GaussKronrod15Rule::kNodes[i];
    Spectrum sum = f(centre - dx) + f(centre + dx);
    kronrod += sum * GaussKronrod15Rule::kKronrodWeights[i];
    if (i % 2 == 1) gauss += sum * GaussKronrod15Rule::kGaussWeights[i / 2];
  }
  return {kronrod * half, gauss * half};
}

}  // namespace skybake::reference
