// Closed-form optics against published values.
#include <cmath>

#include <gtest/gtest.h>

#include "bake/physics.h"

namespace skybake {
namespace {

TEST(Physics, RayleighFormulaReproducesHoffmanPreetham) {
  // Hoffman & Preetham 2002: n = 1.0003, N = 2.545e25 m^-3, p = 0.035 give
  // 6.95e-6, 1.18e-5, 2.44e-5 m^-1 at 650, 570, 475 nm (3 printed digits).
  const double wavelengths_nm[] = {650.0, 570.0, 475.0};
  const double published[] = {6.95e-6, 1.18e-5, 2.44e-5};
  for (int i = 0; i < 3; ++i) {
    double beta = RayleighScatteringCoefficient(1.0003, 2.545e25, 0.035, wavelengths_nm[i] * 1e-9);
    EXPECT_NEAR(beta / published[i], 1.0, 0.005) << wavelengths_nm[i] << " nm: " << beta;
  }
}

TEST(Physics, RayleighFormulaScalesAsInverseFourthPower) {
  double at_400 = RayleighScatteringCoefficient(1.0003, 2.545e25, 0.035, 400e-9);
  double at_800 = RayleighScatteringCoefficient(1.0003, 2.545e25, 0.035, 800e-9);
  EXPECT_NEAR(at_400 / at_800, 16.0, 1e-12);
  // ... and inversely with number density at fixed refractivity.
  double dilute = RayleighScatteringCoefficient(1.0003, 2.0 * 2.545e25, 0.035, 400e-9);
  EXPECT_NEAR(at_400 / dilute, 2.0, 1e-12);
}

TEST(Physics, KingFactor) {
  EXPECT_DOUBLE_EQ(KingFactor(0.0), 1.0);
  EXPECT_DOUBLE_EQ(KingFactor(0.035), 6.105 / 5.755);
  EXPECT_DOUBLE_EQ(KingFactor(0.5), 3.0);
}

TEST(Physics, RayleighLawReproducesBruneton2017Coefficients) {
  // DESIGN.md / Bruneton 2017: 1.24062e-6 * lambda[um]^-4 at 680, 550, 440 nm.
  const double wavelengths_nm[] = {680.0, 550.0, 440.0};
  const double published[] = {5.802e-6, 13.558e-6, 33.100e-6};
  for (int i = 0; i < 3; ++i) {
    double beta = RayleighLawCoefficient(1.24062e-6, wavelengths_nm[i]);
    EXPECT_NEAR(beta / published[i], 1.0, 0.001) << wavelengths_nm[i] << " nm: " << beta;
  }
  EXPECT_DOUBLE_EQ(RayleighLawCoefficient(1.24062e-6, 1000.0), 1.24062e-6);
}

TEST(Physics, AngstromLaw) {
  EXPECT_DOUBLE_EQ(AngstromCoefficient(2e-5, 550.0, 1.3, 550.0), 2e-5);
  EXPECT_DOUBLE_EQ(AngstromCoefficient(2e-5, 550.0, 0.0, 440.0), 2e-5);
  // Halving the wavelength multiplies by 2^alpha.
  EXPECT_NEAR(AngstromCoefficient(1.0, 800.0, 1.3, 400.0), std::pow(2.0, 1.3), 1e-14);
  // Exponent 4 from 1 um is the Rayleigh law.
  EXPECT_NEAR(AngstromCoefficient(1.24062e-6, 1000.0, 4.0, 440.0) /
                  RayleighLawCoefficient(1.24062e-6, 440.0),
              1.0, 1e-14);
}

}  // namespace
}  // namespace skybake
