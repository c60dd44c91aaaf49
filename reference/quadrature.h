// Gauss-Kronrod quadrature (the 7-point Gauss rule embedded in the 15-point
// Kronrod rule, QUADPACK's qk15) for the deterministic integrals of the
// reference solver: optical depths, and the transmittances made from them.
#pragma once

#include "bake/atmosphere.h"

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

namespace detail {
// Abscissae on [-1, 1] (non-negative half, decreasing; index 7 is the
// centre), Kronrod weights, and the Gauss weights of the odd abscissae and
// the centre.
constexpr double kKronrodNodes[8] = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr double kKronrodWeights[8] = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kGaussWeights[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                     0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
}  // namespace detail

template <typename F>
GaussKronrodResult GaussKronrod15(F&& f, double a, double b) {
  const double centre = 0.5 * (a + b), half = 0.5 * (b - a);
  Spectrum f_centre = f(centre);
  Spectrum kronrod = f_centre * detail::kKronrodWeights[7];
  Spectrum gauss = f_centre * detail::kGaussWeights[3];
  for (int i = 0; i < 7; ++i) {
    double dx = half * detail::kKronrodNodes[i];
    Spectrum sum = f(centre - dx) + f(centre + dx);
    kronrod += sum * detail::kKronrodWeights[i];
    if (i % 2 == 1) gauss += sum * detail::kGaussWeights[i / 2];
  }
  return {kronrod * half, gauss * half};
}

}  // namespace skybake::reference
