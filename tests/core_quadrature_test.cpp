// The shared quadrature rules of core/quadrature.h: each integrates the
// polynomials it should exactly, and the tabulated 8-point Gauss-Legendre
// rule is the computed one to the 16 digits it is written with.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/quadrature.h"

namespace skybake {
namespace {

// Integral of x^degree over [a, b].
double Monomial(int degree, double a, double b) {
  return (std::pow(b, degree + 1) - std::pow(a, degree + 1)) / (degree + 1);
}

TEST(CoreQuadrature, GaussLegendreIsExactToDegree2nMinus1OnAnyInterval) {
  for (int n : {1, 2, 5, 8, 17}) {
    std::vector<double> nodes, weights;
    AppendGaussLegendre(n, -0.5, 2.0, nodes, weights);
    ASSERT_EQ(nodes.size(), static_cast<size_t>(n));
    for (int degree = 0; degree <= 2 * n - 1; ++degree) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i) sum += weights[i] * std::pow(nodes[i], degree);
      EXPECT_NEAR(sum, Monomial(degree, -0.5, 2.0), 1e-13 * std::pow(2.0, degree)) << n << " nodes, x^" << degree;
    }
  }
}

TEST(CoreQuadrature, AppendKeepsEarlierNodes) {
  std::vector<double> nodes = {7.0}, weights = {3.0};
  AppendGaussLegendre(4, 0.0, 1.0, nodes, weights);
  ASSERT_EQ(nodes.size(), 5u);
  EXPECT_EQ(nodes[0], 7.0);
  EXPECT_EQ(weights[0], 3.0);
}

TEST(CoreQuadrature, TabulatedEightPointRuleIsTheComputedOne) {
  std::vector<double> nodes, weights;
  AppendGaussLegendre(8, -1.0, 1.0, nodes, weights);
  // AppendGaussLegendre orders the nodes from +1 down; the table from -1 up.
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(GaussLegendre8Rule::kNodes[i], nodes[7 - i], 1e-15) << i;
    EXPECT_NEAR(GaussLegendre8Rule::kWeights[i], weights[7 - i], 1e-15) << i;
  }
}

TEST(CoreQuadrature, GaussKronrod15IsExactToDegree23AndGauss7ToDegree13) {
  for (int degree = 0; degree <= 23; ++degree) {
    double kronrod = GaussKronrod15Rule::kKronrodWeights[7] * std::pow(0.0, degree);
    double gauss = GaussKronrod15Rule::kGaussWeights[3] * std::pow(0.0, degree);
    for (int i = 0; i < 7; ++i) {
      double x = GaussKronrod15Rule::kNodes[i];
      double pair = std::pow(x, degree) + std::pow(-x, degree);
      kronrod += GaussKronrod15Rule::kKronrodWeights[i] * pair;
      if (i % 2 == 1) gauss += GaussKronrod15Rule::kGaussWeights[i / 2] * pair;
    }
    EXPECT_NEAR(kronrod, Monomial(degree, -1.0, 1.0), 1e-15) << "x^" << degree;
    if (degree <= 13) {
      EXPECT_NEAR(gauss, Monomial(degree, -1.0, 1.0), 1e-15) << "x^" << degree;
    }
  }
}

}  // namespace
}  // namespace skybake
