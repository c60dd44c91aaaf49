// The transmittance table (stored as optical depth) against the optical depth
// integrated independently (adaptive Simpson, 1e-9 relative) along each ray.
#include <gtest/gtest.h>

#include <random>

#include "bake/bake.h"
#include "quadrature.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"
#include "test_atmospheres.h"

namespace skybake {
namespace {

// A bake whose transmittance table has the default size; the scattering
// tables are tiny since these tests do not look at them.
const LutSet& EarthTransmittanceBake() {
  static const LutSet luts = [] {
    BakeSettings s;
    s.orders = 1;
    s.scattering_r_size = 2, s.scattering_mu_size = 4, s.scattering_mu_s_size = 2, s.scattering_nu_size = 2;
    return Bake(testing::Earth(), s);
  }();
  return luts;
}

double MaxRelativeError(const Spectrum& got, const Spectrum& expected) {
  double e = 0.0;
  for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(got[c] - expected[c]) / expected[c]);
  return e;
}

TEST(Transmittance, OpticalDepthAtTexelCentresWithinPointOnePercent) {
  const LutSet& luts = EarthTransmittanceBake();
  const Atmosphere& atmosphere = luts.atmosphere;
  const glsl::AtmosphereParameters& p = luts.parameters;
  double worst = 0.0;
  for (int y = 0; y < p.transmittance_height; y += 3) {
    for (int x = 0; x < p.transmittance_width; x += 5) {
      double r, mu;
      glsl::GetRMuFromTransmittanceTextureUv(
          p, glsl::vec2((x + 0.5) / p.transmittance_width, (y + 0.5) / p.transmittance_height), r, mu);
      Spectrum exact = testing::ExactOpticalDepth(atmosphere, r, mu, glsl::DistanceToTopAtmosphereBoundary(p, r, mu));
      glsl::vec4 stored = luts.transmittance.Fetch(x, y);
      if (exact.x <= 0.0) continue;  // at the top, looking up: nothing to compare
      worst = std::max(worst, MaxRelativeError(Spectrum(stored), exact));
    }
  }
  RecordProperty("max_relative_error_texel_centres", std::to_string(worst));
  std::printf("transmittance optical depth, texel centres: max relative error %.3g\n", worst);
  EXPECT_LE(worst, 1e-3);
}

// Between texels the table is bilinear, so its error is the interpolation
// error of the parameterization. Where the optical depth is small (within a
// few km of the top, or across the hard corners of Earth's ozone tent at 10,
// 25 and 40 km) the relative error of a tiny optical depth can reach a few
// percent while the transmittance itself stays within 2e-3 of exact; the
// test bounds both, and prints the worst relative error in the thin regime.
TEST(Transmittance, BetweenTexelsAboveHorizontal) {
  const LutSet& luts = EarthTransmittanceBake();
  const Atmosphere& atmosphere = luts.atmosphere;
  Twin twin(MakeTwinTables(luts));
  const glsl::AtmosphereParameters& p = luts.parameters;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_thick = 0.0, worst_thin = 0.0, worst_transmittance = 0.0;
  for (int i = 0; i < 4000; ++i) {
    double altitude = (p.top_radius - p.bottom_radius) * unit(rng) * unit(rng);  // more samples low down
    double r = p.bottom_radius + altitude;
    double mu = unit(rng);  // 0 (horizontal) to 1 (zenith)
    Spectrum exact = testing::ExactOpticalDepth(atmosphere, r, mu, glsl::DistanceToTopAtmosphereBoundary(p, r, mu));
    Spectrum table = twin.OpticalDepthToTop(r, mu);
    for (int c = 0; c < 3; ++c) {
      if (exact[c] <= 0.0) continue;
      double relative = std::abs(table[c] - exact[c]) / exact[c];
      (exact[c] >= 0.1 ? worst_thick : worst_thin) = std::max(exact[c] >= 0.1 ? worst_thick : worst_thin, relative);
      worst_transmittance = std::max(worst_transmittance, std::abs(std::exp(-table[c]) - std::exp(-exact[c])));
    }
  }
  std::printf("transmittance between texels (mu in [0, 1]): optical depth >= 0.1: max relative error %.3g; "
              "optical depth < 0.1: %.3g; max absolute transmittance error %.3g\n",
              worst_thick, worst_thin, worst_transmittance);
  EXPECT_LE(worst_thick, 1e-2);
  EXPECT_LE(worst_transmittance, 2.5e-3);
}

TEST(Transmittance, NeverAboveOneAndIndependentOfDirection) {
  // T between two points on a ray equals T of the reversed ray (within the
  // table's accuracy) and never exceeds 1.
  const LutSet& luts = EarthTransmittanceBake();
  const glsl::AtmosphereParameters& p = luts.parameters;
  glsl::sampler2D table{&luts.transmittance};
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    double r = p.bottom_radius + 20e3 * unit(rng);
    double mu = 0.2 + 0.8 * unit(rng);
    double d = glsl::DistanceToTopAtmosphereBoundary(p, r, mu) * unit(rng);
    glsl::vec3 forward = glsl::GetTransmittance(p, table, r, mu, d, false);
    double r_d = glsl::RadiusAtDistance(p, r, mu, d);
    double mu_d = glsl::CosineAtDistance(r, mu, d, r_d);
    glsl::vec3 backward = glsl::GetTransmittance(p, table, r_d, -mu_d, d, glsl::RayIntersectsGround(p, r_d, -mu_d));
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(forward[c], 1.0);
      EXPECT_NEAR(forward[c], backward[c], 2e-3 * forward[c] + 1e-12);
    }
  }
}

}  // namespace
}  // namespace skybake
