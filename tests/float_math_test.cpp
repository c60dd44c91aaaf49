// The bake's vectorisable float functions against the standard library in
// double.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/float_math.h"

namespace skybake {
namespace {

TEST(FloatMath, ExpWithinTwoUlpsOverItsRange) {
  double worst = 0.0;
  for (float x = -87.0f; x <= 88.0f; x += 0.001953125f) {
    const double exact = std::exp(double(x));
    worst = std::max(worst, std::abs(ExpFloat(x) - exact) / exact);
  }
  // Two float ulps (2^-23 relative each).
  EXPECT_LT(worst, 2.0 * std::ldexp(1.0, -23));
  // Beyond the range: the ends, never 0, infinite or NaN.
  EXPECT_EQ(ExpFloat(-1000.0f), ExpFloat(-87.0f));
  EXPECT_GT(ExpFloat(-1000.0f), 0.0f);
  EXPECT_EQ(ExpFloat(1000.0f), ExpFloat(88.0f));
  EXPECT_TRUE(std::isfinite(ExpFloat(1000.0f)));
}

TEST(FloatMath, ExponentialTrapezoidMatchesTheExactIntegral) {
  // Integral over [0, h] of a exp(lambda t / h) = h a (exp(lambda) - 1) / lambda.
  const float h = 3.0f, a = 0.7f;
  for (double lambda : {-30.0, -2.0, -0.1000001, -0.0999, -1e-3, -1e-7, 0.0, 1e-7, 1e-3, 0.0999, 0.1000001, 2.0, 30.0}) {
    const double b = a * std::exp(lambda);
    const double exact = lambda == 0.0 ? h * a : h * a * std::expm1(lambda) / lambda;
    const float got = ExponentialTrapezoidFloat(a, float(b), float(lambda), h);
    EXPECT_NEAR(got, exact, 1e-6 * exact) << "lambda " << lambda;
  }
  // An end that underflowed to 0 in float still decays at the given rate.
  EXPECT_NEAR(ExponentialTrapezoidFloat(0.0f, 1.0f, 50.0f, 1.0f), 1.0 / 50.0, 1e-7);
  // Ends rounded apart from lambda never make it negative.
  EXPECT_GE(ExponentialTrapezoidFloat(1e-40f, 0.0f, 0.5f, 1.0f), 0.0f);
}

TEST(FloatMath, Clamp) {
  EXPECT_EQ(ClampFloat(2.0f, -1.0f, 1.0f), 1.0f);
  EXPECT_EQ(ClampFloat(-2.0f, -1.0f, 1.0f), -1.0f);
  EXPECT_EQ(ClampFloat(0.25f, -1.0f, 1.0f), 0.25f);
}

}  // namespace
}  // namespace skybake
