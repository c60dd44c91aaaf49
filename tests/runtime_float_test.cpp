// The runtime's scalar primitives and phase functions compiled with
// Number = float (shaders_runtime/primitives.h), which the bake's vectorised
// loops call, against the same GLSL compiled in double. Each float function is
// evaluated at float arguments and compared with the double original at the
// same arguments, over the ranges the bake feeds it. Tolerances are in units
// of the float unit roundoff eps = 2^-24: a few for each rounding of the
// formula, plus, where it subtracts, the rounding of the difference carried
// through the rest. Then the bake's hoisted float lookups (bake/sun_lookups.h)
// against the double runtime functions they stand for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bake/bake.h"
#include "bake/sun_lookups.h"
#include "shaders_runtime/primitives.h"
#include "shaders_runtime/runtime.h"
#include "test_atmospheres.h"

namespace skybake {
namespace {

const double kEps = std::ldexp(1.0, -24);

struct Planet {
  double bottom, top;
};
// Earth, Mars, and a 2 km fog layer on Earth: the thinnest shell the stress
// set bakes.
const Planet kPlanets[] = {{6360e3, 6420e3}, {3389.5e3, 3389.5e3 + 100e3}, {6360e3, 6362e3}};

std::vector<double> Altitudes(const Planet& planet) {
  std::vector<double> h = {0.0, 1e-3, 1.0, 10.0, 100.0, 1e3};
  for (double a = 2e3; a < planet.top - planet.bottom; a *= 1.7) h.push_back(a);
  h.push_back(planet.top - planet.bottom - 1.0);
  h.push_back(planet.top - planet.bottom);
  return h;
}

std::vector<double> Cosines() {
  std::vector<double> mu = {-1e-3, -1e-6, 0.0, 1e-6, 1e-3};
  for (int i = 0; i <= 128; ++i) mu.push_back(-1.0 + i / 64.0);
  return mu;
}

TEST(RuntimeFloat, DistanceToSphereFromInsideWithinFourUlps) {
  // All terms positive (the root is written without cancellation): about
  // four roundings.
  for (const Planet& planet : kPlanets)
    for (double h : Altitudes(planet))
      for (double mu : Cosines()) {
        const double r = planet.bottom + h;
        const float r_mu = float(r) * float(mu), c = float((planet.top - r) * (planet.top + r));
        const double exact = glsl::DistanceToSphereFromInside(r_mu, c);
        EXPECT_LE(std::abs(glsl_float::DistanceToSphereFromInside(r_mu, c) - exact), 4.0 * kEps * exact)
            << "top " << planet.top << " r " << r << " mu " << mu;
      }
}

TEST(RuntimeFloat, DistanceToHorizonWithinThreeUlps) {
  // r - bottom is exact (Sterbenz), then a product and a square root.
  for (const Planet& planet : kPlanets)
    for (double h : Altitudes(planet)) {
      const float bottom = float(planet.bottom), r = float(planet.bottom + h);
      const double exact = glsl::DistanceToHorizon(bottom, r);
      EXPECT_LE(std::abs(glsl_float::DistanceToHorizon(bottom, r) - exact), 3.0 * kEps * exact) << r;
    }
}

TEST(RuntimeFloat, HorizonZenithCosineWithinFourUlps) {
  // The distance to the horizon (three roundings) over r (one more).
  for (const Planet& planet : kPlanets)
    for (double h : Altitudes(planet)) {
      const float bottom = float(planet.bottom), r = float(planet.bottom + h);
      const double exact = glsl::HorizonZenithCosine(bottom, r);
      EXPECT_LE(std::abs(glsl_float::HorizonZenithCosine(bottom, r) - exact), 4.0 * kEps * std::abs(exact)) << h;
    }
}

TEST(RuntimeFloat, SunVisibleFractionWithinTenUlps) {
  // mu_s - horizon is exact near the horizon (Sterbenz); the step's
  // argument carries about four roundings, the smooth step's slope is at
  // most 1.5, and its polynomial adds three.
  const double angular_radius = 0.004675;
  for (const Planet& planet : kPlanets)
    for (double h : Altitudes(planet)) {
      const double r = planet.bottom + h, sin_horizon = planet.bottom / r;
      const float horizon = float(glsl::HorizonZenithCosine(planet.bottom, r)), half_disc = float(sin_horizon * angular_radius);
      for (int i = -300; i <= 300; ++i) {
        const float mu_s = horizon + float(i) * half_disc / 100.0f;
        const double exact = glsl::SunVisibleFractionAboveHorizon(mu_s, horizon, half_disc);
        EXPECT_LE(std::abs(glsl_float::SunVisibleFractionAboveHorizon(mu_s, horizon, half_disc) - exact), 10.0 * kEps)
            << "altitude " << h << " step " << i;
      }
    }
}

TEST(RuntimeFloat, ScatteringUnitCoordinatesWithinFourUlps) {
  // The product, the subtraction from 1 and the division add an absolute
  // error of at most about 3 eps times the size of a / A, which exceeds 1
  // below scattering_mu_s_min (a > A, a negative result).
  for (double big_a : {1e-3, 0.05, 0.3, 0.6, 1.0})
    for (int i = 0; i <= 1000; ++i) {
      const float a = float(i / 1000.0), inverse_a = float(1.0 / big_a);
      EXPECT_LE(std::abs(glsl_float::ScatteringUnitMuSFromDistance(a, inverse_a) -
                         glsl::ScatteringUnitMuSFromDistance(a, inverse_a)),
                4.0 * kEps * std::max(1.0, double(a) * inverse_a))
          << "a " << a << " A " << big_a;
    }
  for (double nu : Cosines())
    EXPECT_LE(std::abs(glsl_float::ScatteringUnitNu(float(nu)) - glsl::ScatteringUnitNu(float(nu))), kEps) << nu;
}

TEST(RuntimeFloat, PhaseFunctionsWithinTheirConditioning) {
  // 1 + g^2 - 2 g nu cancels for strong forward lobes looking at the sun:
  // its relative error is 3 eps (1 + g^2 + 2 |g nu|) / denom, carried with a
  // power 3/2; 1 - g^2 cancels as |g| -> 1, relative error 2 eps / (1 - g^2);
  // plus about six roundings in the rest.
  EXPECT_LE(std::abs(glsl_float::IsotropicPhaseFunction() - glsl::IsotropicPhaseFunction()),
            kEps * glsl::IsotropicPhaseFunction());
  for (double nu : Cosines()) {
    const float n = float(nu);
    const double rayleigh = glsl::RayleighPhaseFunction(n);
    EXPECT_LE(std::abs(glsl_float::RayleighPhaseFunction(n) - rayleigh), 4.0 * kEps * rayleigh) << nu;
    for (double g_value : {-0.9, -0.5, 0.0, 0.3, 0.76, 0.9, 0.99}) {
      const float g = float(g_value);
      const double denom = 1.0 + double(g) * g - 2.0 * double(g) * n;
      const double tolerance = 1.5 * 3.0 * kEps * (1.0 + double(g) * g + 2.0 * std::abs(double(g) * n)) / denom +
                               2.0 * kEps / (1.0 - double(g) * g) + 6.0 * kEps;
      const double hg = glsl::HenyeyGreensteinPhaseFunction(g, n), cs = glsl::CornetteShanksPhaseFunction(g, n);
      EXPECT_LE(std::abs(glsl_float::HenyeyGreensteinPhaseFunction(g, n) - hg), tolerance * hg) << g << " " << nu;
      EXPECT_LE(std::abs(glsl_float::CornetteShanksPhaseFunction(g, n) - cs), (tolerance + 4.0 * kEps) * cs)
          << g << " " << nu;
    }
  }
}

// A transmittance table filled with a smooth function of the texel (no
// table of a bake is needed to check where the float lookups read): the
// value at texel (x, y) and its largest change from one texel to the next.
double SyntheticDepth(double x, double y) { return 1.0 + 0.5 * std::sin(0.05 * x) + 0.3 * std::cos(0.11 * y); }
constexpr double kSyntheticSlope = 0.5 * 0.05 + 0.3 * 0.11;

glsl::Texture SyntheticTransmittance(const glsl::AtmosphereParameters& p) {
  glsl::Texture table(p.transmittance_width, p.transmittance_height);
  for (int y = 0; y < table.height; ++y)
    for (int x = 0; x < table.width; ++x) {
      const double depth = SyntheticDepth(x, y);
      table.Store(x, y, 0, glsl::vec4(depth, 2.0 * depth, 3.0 * depth, 0.0));
    }
  return table;
}

TEST(RuntimeFloat, HoistedSunLookupsReadWhereTheRuntimeReads) {
  // The float texel positions carry about ten roundings of a value below
  // the table's width (256): under 1e-4 texels, times the table's slope;
  // the blends of values near 2 add a few eps each.
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(testing::Earth(), BakeSettings{});
  const glsl::Texture table = SyntheticTransmittance(p);
  const detail::ChannelPlanes planes(table);
  detail::SunAtRadius at_radius(p, planes);
  const detail::SunAtPoints at_points(p, planes);
  const double tolerance = 1e-4 * 3.0 * kSyntheticSlope + 16.0 * kEps * 3.0 * 1.8;
  std::vector<float> mu_s;
  for (double mu : Cosines()) mu_s.push_back(float(mu));
  const int count = int(mu_s.size());
  for (double h : {0.0, 1.0, 100.0, 1e3, 8e3, 30e3, 59.9e3, 60e3}) {
    const double r = float(p.bottom_radius + h);  // as the float lookups see it
    std::vector<float> tau[3], tau_points[3], radii(count, float(r));
    for (int c = 0; c < 3; ++c) tau[c].resize(count), tau_points[c].resize(count);
    std::vector<float> visible(count), visible_points(count);
    at_radius.SetRadius(r);
    at_radius.Visible(mu_s.data(), count, visible.data());
    at_radius.OpticalDepth(mu_s.data(), 0, count, tau);
    at_points.Evaluate(radii.data(), mu_s.data(), count, tau_points, visible_points.data());
    for (int j = 0; j < count; ++j) {
      const glsl::vec3 exact =
          glsl::GetOpticalDepthToTopAtmosphereBoundary(p, glsl::sampler2D{&table}, r, mu_s[j]);
      const double fraction = glsl::SunVisibleFraction(p, r, mu_s[j]);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(tau[c][j], exact[c], tolerance) << "altitude " << h << " mu_s " << mu_s[j];
        EXPECT_NEAR(tau_points[c][j], exact[c], tolerance) << "altitude " << h << " mu_s " << mu_s[j];
      }
      EXPECT_NEAR(visible[j], fraction, 10.0 * kEps) << "altitude " << h << " mu_s " << mu_s[j];
      EXPECT_NEAR(visible_points[j], fraction, 10.0 * kEps) << "altitude " << h << " mu_s " << mu_s[j];
    }
  }
}

TEST(RuntimeFloat, HoistedMuSTapsMatchTheRuntimesCoordinate) {
  // The position along mu_s (at most size - 1 = 31 texels) carries about ten
  // roundings: under 1e-4 texels.
  for (double mu_s_min : {-0.2, -0.5}) {
    glsl::AtmosphereParameters p = MakeAtmosphereParameters(testing::Earth(), BakeSettings{});
    p.scattering_mu_s_min = mu_s_min;
    const detail::MuSCoordinate coordinate(p);
    std::vector<float> mu_s;
    for (double mu : Cosines()) mu_s.push_back(float(mu));
    const int count = int(mu_s.size());
    std::vector<int> left(count);
    std::vector<float> weight(count);
    coordinate.Taps(mu_s.data(), count, left.data(), weight.data());
    for (int j = 0; j < count; ++j) {
      const double exact = std::clamp(glsl::GetScatteringTextureUMuS(p, mu_s[j]) * p.scattering_mu_s_size - 0.5, 0.0,
                                      double(p.scattering_mu_s_size - 1));
      EXPECT_NEAR(left[j] + weight[j], exact, 1e-4) << "mu_s_min " << mu_s_min << " mu_s " << mu_s[j];
    }
  }
}

}  // namespace
}  // namespace skybake
