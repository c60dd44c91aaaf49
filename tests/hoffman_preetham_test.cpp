// Hoffman & Preetham's analytic model (shaders_runtime/hoffman_preetham.glsl)
// against brute-force quadrature of the physics it claims to solve: single
// scattering of constant sunlight in constant-density media. The quadrature
// (tests/quadrature.h, adaptive Simpson) integrates the scattered light along
// the ray point by point and knows nothing of the closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "quadrature.h"
#include "shaders_runtime/hoffman_preetham.h"

namespace skybake {
namespace {

using glsl::HoffmanPreethamParameters;
using glsl::vec3;

// Air as Hoffman & Preetham's Rayleigh coefficients at 650/570/475 nm plus a
// little absorption, and their "heavy haze" with measured forward scattering.
HoffmanPreethamParameters HazyAir() {
  HoffmanPreethamParameters p;
  p.sun_irradiance = vec3(1.474, 1.8504, 1.91198);
  p.sun_angular_radius = 0.004675;
  p.air_scattering = vec3(6.95e-6, 1.18e-5, 2.44e-5);
  p.air_extinction = p.air_scattering + vec3(6.5e-7, 1.881e-6, 8.5e-8);
  p.haze_scattering = vec3(8e-5, 1e-4, 1.2e-4);
  p.haze_extinction = p.haze_scattering / 0.9;
  p.haze_g = 0.76;
  p.air_zenith_optical_length = 8400.0;
  p.haze_zenith_optical_length = 1250.0;
  p.horizon_cos = 0.0;
  return p;
}

double RelativeDifference(const vec3& a, const vec3& b) {
  vec3 d = abs(a - b) / max(abs(b), vec3(1e-300));
  return std::max({d.x, d.y, d.z});
}

// The closed forms are exact; what remains is the series for
// (1 - exp(-x)) / k below x = 0.1 (relative truncation error < x^5 / 720 <
// 1.4e-8 at x = 0.1) and the quadrature's tolerance (~1e-9 relative).
constexpr double kTolerance = 5e-8;

TEST(HoffmanPreetham, PhaseFunctionsIntegrateToOne) {
  auto over_sphere = [](auto phase) {
    return testing::Integrate<double>([&](double mu) { return 2.0 * M_PI * phase(mu); }, -1.0, 1.0, 1e-12, 256);
  };
  EXPECT_NEAR(over_sphere([](double mu) { return glsl::RayleighPhaseFunction(mu); }), 1.0, 1e-9);
  for (double g : {-0.5, 0.0, 0.76, 0.9}) {
    EXPECT_NEAR(over_sphere([g](double mu) { return glsl::HenyeyGreensteinPhaseFunction(g, mu); }), 1.0, 1e-9)
        << g;
  }
}

TEST(HoffmanPreetham, InScatteringAndExtinctionMatchQuadratureOfAConstantDensityMedium) {
  HoffmanPreethamParameters p = HazyAir();
  vec3 beta = p.air_extinction + p.haze_extinction;
  for (double cos_theta : {-1.0, 0.0, 0.7, 0.999}) {
    vec3 angular = p.air_scattering * glsl::RayleighPhaseFunction(cos_theta) +
                   p.haze_scattering * glsl::HenyeyGreensteinPhaseFunction(p.haze_g, cos_theta);
    // 10 m (x ~ 1e-3, the series) to 100 km (x ~ 14, the quotient).
    for (double s : {10.0, 300.0, 1000.0, 5000.0, 100000.0}) {
      SCOPED_TRACE("cos_theta " + std::to_string(cos_theta) + ", s " + std::to_string(s));
      vec3 integral = testing::Integrate<vec3>(
          [&](double t) { return angular * p.sun_irradiance * exp(-beta * t); }, 0.0, s, 1e-11 * s * 1e-3, 64);
      EXPECT_LT(RelativeDifference(glsl::HoffmanPreethamInScattering(p, s, cos_theta, p.sun_irradiance), integral),
                kTolerance);
      vec3 transmittance = glsl::HoffmanPreethamExtinction(p, s);
      vec3 optical_depth = testing::Integrate<vec3>([&](double) { return beta; }, 0.0, s, 1e-12 * s * 1e-3);
      EXPECT_LT(RelativeDifference(transmittance, exp(-optical_depth)), 1e-12);
    }
  }
}

// The two-shell sky: both constituents scatter out to the nearer shell, only
// the longer one beyond it, all seen through what lies in front.
TEST(HoffmanPreetham, TwoShellSkyMatchesQuadratureOfTwoNestedShells) {
  HoffmanPreethamParameters p = HazyAir();
  const double cos_theta = 0.5;
  vec3 air = p.air_scattering * glsl::RayleighPhaseFunction(cos_theta);
  vec3 haze = p.haze_scattering * glsl::HenyeyGreensteinPhaseFunction(p.haze_g, cos_theta);
  for (auto [air_length, haze_length] : {std::pair{8400.0, 1250.0}, {1250.0, 8400.0}, {30000.0, 30000.0},
                                        {50.0, 20.0}}) {
    SCOPED_TRACE(std::to_string(air_length) + " m of air, " + std::to_string(haze_length) + " m of haze");
    auto in_shell = [](double t, double length) { return t < length ? 1.0 : 0.0; };
    auto radiance = [&](double t) {
      double a = in_shell(t, air_length), h = in_shell(t, haze_length);
      vec3 depth = p.air_extinction * std::min(t, air_length) + p.haze_extinction * std::min(t, haze_length);
      return (a * air + h * haze) * p.sun_irradiance * exp(-depth);
    };
    double near = std::min(air_length, haze_length), far = std::max(air_length, haze_length);
    vec3 integral = testing::Integrate<vec3>(radiance, 0.0, near, 1e-14 * near, 64);
    if (far > near) integral += testing::Integrate<vec3>(radiance, near, far, 1e-14 * far, 64);
    EXPECT_LT(RelativeDifference(
                  glsl::HoffmanPreethamSkyRadiance(p, air_length, haze_length, cos_theta, p.sun_irradiance), integral),
              kTolerance);
    EXPECT_LT(RelativeDifference(glsl::HoffmanPreethamSkyTransmittance(p, air_length, haze_length),
                                 exp(-(p.air_extinction * air_length + p.haze_extinction * haze_length))),
              1e-15);
  }
  // Equal shells are Hoffman & Preetham's L_in.
  EXPECT_LT(RelativeDifference(glsl::HoffmanPreethamSkyRadiance(p, 4000.0, 4000.0, cos_theta, p.sun_irradiance),
                               glsl::HoffmanPreethamInScattering(p, 4000.0, cos_theta, p.sun_irradiance)),
            1e-14);
}

TEST(HoffmanPreetham, SunlightIsAttenuatedAlongBothOpticalLengthsAndSetsBelowTheHorizon) {
  HoffmanPreethamParameters p = HazyAir();
  vec3 overhead = glsl::HoffmanPreethamSunIrradiance(p, 1.0, 1.0, 1.0);
  vec3 expected = p.sun_irradiance * exp(-(p.air_extinction * 8400.0 + p.haze_extinction * 1250.0));
  EXPECT_LT(RelativeDifference(overhead, expected), 1e-14);
  // Twice the relative path: the square of the transmittance.
  vec3 low = glsl::HoffmanPreethamSunIrradiance(p, 0.5, 2.0, 2.0);
  EXPECT_LT(RelativeDifference(low, expected * expected / p.sun_irradiance), 1e-14);
  // The disc straddling the horizon is half visible; one radius below, hidden.
  vec3 half = glsl::HoffmanPreethamSunIrradiance(p, 0.0, 1.0, 1.0);
  EXPECT_LT(RelativeDifference(half, 0.5 * overhead), 1e-14);
  vec3 below = glsl::HoffmanPreethamSunIrradiance(p, -p.sun_angular_radius, 1.0, 1.0);
  EXPECT_EQ(below.x + below.y + below.z, 0.0);
}

}  // namespace
}  // namespace skybake
