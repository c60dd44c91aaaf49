// Phase functions: normalization over the sphere and first moments, checked
// with a quadrature that is itself checked against a closed form.
//
// Why the quadrature is exact enough: for |g| -> 1 Henyey-Greenstein and
// Cornette-Shanks behave like (1 + g^2 - 2 g mu)^(-3/2), a peak at mu = +-1 of
// width (1 - |g|)^2 / (2|g|) ~ 5e-7 for g = 0.999 and height ~ 1e5. Gauss-Legendre
// on [-1, 1] would miss it entirely. Instead [-1, 1] is cut at 1 - 10^-k and
// -1 + 10^-k (k = 1..15): on every piece the nearest singularity of the
// integrand (mu = (1 + g^2) / (2g), just outside [-1, 1]) lies at least a
// fifth of the piece's length away, so a 32-point rule converges like
// rho^-64 with rho >= 1.6 (below 1e-13). What limits the result is double
// precision itself: mu near 1 is rounded to ~1e-16, which moves the distance
// to a 5e-7-wide peak by ~2e-10 relative. The tests confirm both instead of
// trusting them: the rule reproduces the closed-form integral of exactly that
// singular shape, and 24- and 32-point results agree, to 1e-9 -- three orders
// below the 1e-6 asked of the phase functions.
#include <cmath>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "core/quadrature.h"

namespace skybake {
namespace {

struct GaussLegendre {
  std::vector<double> nodes, weights;  // on [-1, 1]
};

GaussLegendre MakeGaussLegendre(int n) {
  GaussLegendre rule;
  AppendGaussLegendre(n, -1.0, 1.0, rule.nodes, rule.weights);
  return rule;
}

// Integral of f over [-1, 1] on a mesh graded geometrically towards both ends.
double IntegrateOverMu(const std::function<double(double)>& f, int order) {
  std::vector<double> cuts = {-1.0};
  for (int k = 15; k >= 1; --k) cuts.push_back(-1.0 + std::pow(10.0, -k));
  for (int k = 1; k <= 15; ++k) cuts.push_back(1.0 - std::pow(10.0, -k));
  cuts.push_back(1.0);
  GaussLegendre rule = MakeGaussLegendre(order);
  double sum = 0.0;
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    double mid = 0.5 * (cuts[i] + cuts[i + 1]), half = 0.5 * (cuts[i + 1] - cuts[i]);
    for (size_t j = 0; j < rule.nodes.size(); ++j)
      sum += half * rule.weights[j] * f(mid + half * rule.nodes[j]);
  }
  return sum;
}

// Integral over the sphere of phase(mu) * mu^power (azimuth contributes 2 pi).
double SphereMoment(const PhaseFunction& phase, int power, int order = 32) {
  return 2.0 * kPi * IntegrateOverMu(
                         [&](double mu) { return phase.Evaluate(mu) * std::pow(mu, power); },
                         order);
}

const double kAsymmetries[] = {-0.999, -0.9, -0.5, 0.0, 0.5, 0.8, 0.9, 0.99, 0.999};

std::vector<PhaseFunction> AllPhaseFunctions() {
  std::vector<PhaseFunction> result = {{PhaseKind::kIsotropic, 0.0}, {PhaseKind::kRayleigh, 0.0}};
  for (double g : kAsymmetries) {
    result.push_back({PhaseKind::kHenyeyGreenstein, g});
    result.push_back({PhaseKind::kCornetteShanks, g});
  }
  return result;
}

TEST(PhaseQuadrature, IsExactForPolynomials) {
  GaussLegendre rule = MakeGaussLegendre(32);
  for (int degree = 0; degree <= 63; ++degree) {
    double sum = 0.0;
    for (size_t j = 0; j < rule.nodes.size(); ++j)
      sum += rule.weights[j] * std::pow(rule.nodes[j], degree);
    double exact = degree % 2 ? 0.0 : 2.0 / (degree + 1);
    EXPECT_NEAR(sum, exact, 1e-14) << "x^" << degree;
  }
}

TEST(PhaseQuadrature, ResolvesTheForwardPeakShape) {
  // integral over [-1, 1] of (a - x)^(-3/2) = 2 [(a - 1)^(-1/2) - (a + 1)^(-1/2)],
  // with a - 1 the peak width of g = 0.999.
  double g = 0.999;
  double a = (1.0 + g * g) / (2.0 * g);
  double exact = 2.0 * (1.0 / std::sqrt(a - 1.0) - 1.0 / std::sqrt(a + 1.0));
  double numeric = IntegrateOverMu([&](double x) { return std::pow(a - x, -1.5); }, 32);
  EXPECT_NEAR(numeric / exact, 1.0, 1e-9);
}

TEST(PhaseFunction, EveryPhaseFunctionIntegratesToOne) {
  for (const PhaseFunction& phase : AllPhaseFunctions()) {
    SCOPED_TRACE(std::string(ToString(phase.kind)) + " g = " + std::to_string(phase.g));
    double fine = SphereMoment(phase, 0, 32);
    double coarse = SphereMoment(phase, 0, 24);
    EXPECT_NEAR(fine, coarse, 1e-9) << "quadrature not converged";
    EXPECT_NEAR(fine, 1.0, 1e-6);
  }
}

TEST(PhaseFunction, HenyeyGreensteinMeanCosineIsG) {
  // This is what g means for Henyey-Greenstein; the (1 - g)^2 misprint of the
  // Hoffman-Preetham paper would break the normalization test above instead.
  for (double g : kAsymmetries) {
    EXPECT_NEAR(SphereMoment({PhaseKind::kHenyeyGreenstein, g}, 1), g, 1e-9) << "g = " << g;
  }
}

TEST(PhaseFunction, CornetteShanksMeanCosine) {
  // Cornette & Shanks 1992: <mu> = 3 g (4 + g^2) / (5 (2 + g^2)), not g itself.
  for (double g : kAsymmetries) {
    double expected = 3.0 * g * (4.0 + g * g) / (5.0 * (2.0 + g * g));
    EXPECT_NEAR(SphereMoment({PhaseKind::kCornetteShanks, g}, 1), expected, 1e-9) << "g = " << g;
  }
}

TEST(PhaseFunction, SymmetricFunctionsHaveNoMeanCosine) {
  EXPECT_NEAR(SphereMoment({PhaseKind::kIsotropic, 0.0}, 1), 0.0, 1e-13);
  EXPECT_NEAR(SphereMoment({PhaseKind::kRayleigh, 0.0}, 1), 0.0, 1e-13);
}

TEST(PhaseFunction, CornetteShanksWithZeroGIsRayleigh) {
  PhaseFunction cornette_shanks{PhaseKind::kCornetteShanks, 0.0};
  PhaseFunction rayleigh{PhaseKind::kRayleigh, 0.0};
  for (double mu = -1.0; mu <= 1.0; mu += 0.125)
    EXPECT_NEAR(cornette_shanks.Evaluate(mu), rayleigh.Evaluate(mu), 1e-15) << "mu = " << mu;
}

TEST(PhaseFunction, FinitePositiveAndPeakedTheRightWay) {
  for (const PhaseFunction& phase : AllPhaseFunctions()) {
    SCOPED_TRACE(std::string(ToString(phase.kind)) + " g = " + std::to_string(phase.g));
    for (double mu : {-1.0, -0.5, 0.0, 0.5, 1.0}) {
      double value = phase.Evaluate(mu);
      EXPECT_TRUE(std::isfinite(value));
      EXPECT_GT(value, 0.0);
    }
    if (phase.g > 0) {
      EXPECT_GT(phase.Evaluate(1.0), phase.Evaluate(-1.0));
    } else if (phase.g < 0) {
      EXPECT_LT(phase.Evaluate(1.0), phase.Evaluate(-1.0));
    }
  }
}

}  // namespace
}  // namespace skybake
