// Ray-sphere distances must stay accurate where the textbook formula
// -r mu +/- sqrt(r^2 (mu^2 - 1) + R^2) cancels catastrophically: observers a
// few millimetres above the ground and rays a tenth of a microradian off the
// horizon. The reference evaluates the textbook roots in long double, with the
// discriminant formed as (R - r)(R + r) + (r mu)^2, whose factors are exact
// for double inputs (forming r^2 - R^2 directly would cancel even in long
// double, leaving the reference less accurate than the code under test).
#include <gtest/gtest.h>

#include <cmath>

#include "shaders_runtime/runtime.h"

namespace skybake {
namespace {

constexpr double kBottom = 6360e3, kTop = 6420e3;

glsl::AtmosphereParameters Planet() {
  glsl::AtmosphereParameters p;
  p.bottom_radius = kBottom;
  p.top_radius = kTop;
  return p;
}

long double Discriminant(long double r, long double mu, long double R) {
  return (R - r) * (R + r) + (r * mu) * (r * mu);
}

long double LongDoubleDistanceToTop(long double r, long double mu) {
  return -r * mu + std::sqrt(Discriminant(r, mu, kTop));
}

long double LongDoubleDistanceToBottom(long double r, long double mu) {
  return -r * mu - std::sqrt(Discriminant(r, mu, kBottom));
}

double NaiveDistanceToBottom(double r, double mu) {
  return -r * mu - std::sqrt(r * r * (mu * mu - 1.0) + kBottom * kBottom);
}

const double kRadii[] = {kBottom, kBottom * (1.0 + 1e-9), kBottom + 1.0, kBottom + 1e3, kTop * (1.0 - 1e-9), kTop};
const double kCosines[] = {-1.0, -0.5, -1e-2, -1e-4, -1e-7, 0.0, 1e-7, 1e-4, 1e-2, 0.5, 1.0};

TEST(Geometry, DistanceToTopMatchesLongDouble) {
  for (double r : kRadii) {
    for (double mu : kCosines) {
      long double expected = LongDoubleDistanceToTop(r, mu);
      double got = glsl::DistanceToTopAtmosphereBoundary(Planet(), r, mu);
      double tolerance = 1e-12 * double(expected) + 1e-9;  // 1 nm absolute where the distance is ~0
      EXPECT_NEAR(got, double(expected), tolerance) << "r = " << r << " mu = " << mu;
    }
  }
}

TEST(Geometry, DistanceToBottomMatchesLongDouble) {
  int checked = 0;
  for (double r : kRadii) {
    for (double mu : kCosines) {
      if (!glsl::RayIntersectsGround(Planet(), r, mu)) continue;
      long double expected = LongDoubleDistanceToBottom(r, mu);
      double got = glsl::DistanceToBottomAtmosphereBoundary(Planet(), r, mu);
      EXPECT_NEAR(got, double(expected), 1e-12 * double(expected) + 1e-9) << "r = " << r << " mu = " << mu;
      ++checked;
    }
  }
  EXPECT_GE(checked, 18);
}

// The case the robust form exists for: 6.36 mm above the ground looking 0.01
// down, the ground is 6.4 cm away; the naive double formula subtracts two
// numbers near 6.4e4 m and keeps about 7 significant digits.
TEST(Geometry, NaiveFormulaWouldFailWhereRobustOneHolds) {
  double r = kBottom * (1.0 + 1e-9), mu = -1e-2;
  long double expected = LongDoubleDistanceToBottom(r, mu);
  double robust = glsl::DistanceToBottomAtmosphereBoundary(Planet(), r, mu);
  double naive = NaiveDistanceToBottom(r, mu);
  double robust_error = std::abs(robust - double(expected)) / double(expected);
  double naive_error = std::abs(naive - double(expected)) / double(expected);
  EXPECT_LT(robust_error, 1e-13);
  EXPECT_GT(naive_error, 1e-10);
}

TEST(Geometry, GrazingRaysClassifiedConsistently) {
  // Just above the ground, a ray a tenth of a microradian below the horizon
  // still misses the ground only if its lowest point stays above it.
  double r = kBottom * (1.0 + 1e-9);
  double mu_horizon = -std::sqrt(1.0 - (kBottom / r) * (kBottom / r));
  EXPECT_TRUE(glsl::RayIntersectsGround(Planet(), r, mu_horizon * 1.001));
  EXPECT_FALSE(glsl::RayIntersectsGround(Planet(), r, mu_horizon * 0.999));
  EXPECT_FALSE(glsl::RayIntersectsGround(Planet(), r, 1e-7));
}

}  // namespace
}  // namespace skybake
