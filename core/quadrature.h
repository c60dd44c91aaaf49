// Quadrature rules shared by the bake, the fit and the reference solver.
#pragma once

#include <vector>

namespace skybake {

// The n-point Gauss-Legendre rule mapped to [a, b], appended to nodes and
// weights. The nodes x_i on [-1, 1] are the roots of the Legendre polynomial
// P_n, found by Newton's method from the guess cos(pi (i + 3/4) / (n + 1/2))
// with P_n and P_n' from the recurrence k P_k = (2k - 1) x P_(k-1) - (k - 1) P_(k-2);
// the weights are 2 / ((1 - x_i^2) P_n'(x_i)^2), scaled by (b - a) / 2.
void AppendGaussLegendre(int n, double a, double b, std::vector<double>& nodes, std::vector<double>& weights);

// The 8-point Gauss-Legendre rule on [-1, 1], tabulated to 16 significant
// digits: the values the optical depths of the transmittance table
// (bake/medium.cpp) are computed with. AppendGaussLegendre(8, -1, 1, ...)
// lands within a few ulps of them but not on them, and the tables derived
// from the transmittance would change in their last bits.
struct GaussLegendre8Rule {
  static constexpr double kNodes[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                       -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                       0.7966664774136267,  0.9602898564975363};
  static constexpr double kWeights[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                         0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                         0.2223810344533745, 0.1012285362903763};
};

// QUADPACK's qk15: the 7-point Gauss rule embedded in the 15-point Kronrod
// rule on [-1, 1]. The abscissae are the non-negative half, decreasing, with
// the centre last (index 7); the Gauss rule uses the odd-indexed abscissae
// and the centre, so |Kronrod - Gauss| estimates the Gauss rule's error.
struct GaussKronrod15Rule {
  static constexpr double kNodes[8] = {
      0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
      0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
      0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
      0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
  static constexpr double kKronrodWeights[8] = {
      0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
      0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
      0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
      0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
  // For the abscissae 1, 3, 5 and the centre 7.
  static constexpr double kGaussWeights[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                              0.381830050505118944950369775488975, 0.417959183673469387755102040816327};
};

}  // namespace skybake
