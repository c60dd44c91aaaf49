// The stress set: every atmosphere bakes with --orders auto at small tables
// and passes the invariants on every texel and on 100,000 random twin
// queries; the white-ground, non-absorbing one sends back what it receives.
// The checker and the energy integral are tested first on cases with known
// answers, so that a checker that never fires cannot pass for a clean bake.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "bake/energy_balance.h"
#include "bake/invariants.h"
#include "bake/stress_set.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

constexpr int kQueries = 100000;
constexpr std::uint64_t kSeed = 7;

std::string Examples(const InvariantReport& r) {
  std::string text;
  for (const std::string& e : r.examples) text += "\n  " + e;
  return text;
}

class StressSetTest : public ::testing::TestWithParam<int> {};

TEST_P(StressSetTest, NoInvariantViolations) {
  const StressAtmosphere stress = StressSet()[GetParam()];
  StressResult r = RunStress(stress, WithEnergyBalanceResolution(stress, StressBakeSettings()), kQueries, kSeed);
  EXPECT_EQ(r.tables.violations, 0) << Examples(r.tables);
  EXPECT_EQ(r.queries.violations, 0) << Examples(r.queries);
  EXPECT_GE(r.queries.values_checked, 3 * kQueries);
  Spectrum out = r.energy.Outgoing();
  if (stress.must_balance_energy) {
    EXPECT_LT(r.bake.remaining_error, 1e-4);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(out[c], 1.0, kEnergyBalanceTolerance) << "channel " << c;
  }
  std::printf("%s: orders %d, remaining %.3g, %lld values, energy out %.4f %.4f %.4f, %.2f s\n",
              stress.atmosphere.name.c_str(), r.bake.orders_used, r.bake.remaining_error,
              static_cast<long long>(r.tables.values_checked + r.queries.values_checked), out.x, out.y, out.z,
              r.seconds);
}

INSTANTIATE_TEST_SUITE_P(Atmospheres, StressSetTest, ::testing::Range(0, static_cast<int>(StressSet().size())),
                         [](const ::testing::TestParamInfo<int>& info) {
                           std::string name = StressSet()[info.param].atmosphere.name;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(StressSet, PresetsHaveNoInvariantViolations) {
  for (const PresetInfo& preset : ListPresets()) {
    StressResult r = RunStress(StressAtmosphere{LoadPreset(preset.name), false}, StressBakeSettings(), kQueries, kSeed);
    EXPECT_EQ(r.tables.violations, 0) << preset.name << Examples(r.tables);
    EXPECT_EQ(r.queries.violations, 0) << preset.name << Examples(r.queries);
  }
}

TEST(StressSet, EveryAtmosphereSurvivesItsOwnFileFormat) {
  // The manifest stores the atmosphere as TOML and loaders parse it back.
  for (const StressAtmosphere& s : StressSet()) {
    EXPECT_EQ(ToToml(ParseAtmosphere(ToToml(s.atmosphere), s.atmosphere.name)), ToToml(s.atmosphere))
        << s.atmosphere.name;
  }
}

TEST(StressCommand, ReportsEachAtmosphereAndRejectsBadOptions) {
  testing::TempDir dir;
  std::string out, err;
  const std::string stress = testing::Skybake() + " stress --queries 1000";
  ASSERT_EQ(testing::RunCommand(stress + " --only no-constituents --only earth", dir, &out, &err), 0) << err;
  std::vector<std::string> lines = testing::Lines(out);
  ASSERT_EQ(lines.size(), 3u) << out;  // header and one line each
  EXPECT_EQ(lines[1].rfind("no-constituents", 0), 0u);
  EXPECT_EQ(lines[2].rfind("earth", 0), 0u);
  ASSERT_EQ(testing::RunCommand(stress + " --only no-constituents --json", dir, &out, &err), 0) << err;
  nlohmann::json j = nlohmann::json::parse(out);
  ASSERT_EQ(j.size(), 1u);
  EXPECT_EQ(j[0]["violations"], 0);
  EXPECT_EQ(j[0]["orders_used"], 2);
  EXPECT_EQ(testing::RunCommand(stress + " --only no-such-atmosphere", dir, &out, &err), 1);
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_EQ(testing::RunCommand(testing::Skybake() + " stress --queries -1", dir, &out, &err), 2);
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
}

// A vacuum over a ground of albedo a: the sun's flux on the planet's disc,
// pi R_g^2 E, is reflected with factor a, and the ring between R_g and R_top
// passes untouched, so outgoing / incoming = a (R_g / R_top)^2 + 1 - (R_g / R_top)^2.
TEST(EnergyBalance, VacuumOverAGroundMatchesGeometry) {
  Atmosphere a = testing::Earth();
  a.constituents.clear();
  a.mu_s_min = -1.0;
  a.ground_albedo = Spectrum(1.0, 0.5, 0.0);
  BakeSettings settings = StressBakeSettings();
  EnergyBalance balance = ComputeEnergyBalance(Bake(a, settings));
  const double disc = (a.bottom_radius_m / a.top_radius_m) * (a.bottom_radius_m / a.top_radius_m);
  for (int c = 0; c < 3; ++c) {
    // Midpoint sums of smooth integrands (cosines) with 128 x 24 x 24 nodes:
    // errors of order 1e-4; 2e-3 leaves room for the sun's smoothstep edge.
    EXPECT_NEAR(balance.Outgoing()[c], a.ground_albedo[c] * disc + 1.0 - disc, 2e-3) << "channel " << c;
  }
  EXPECT_NEAR(balance.transmitted.x, 1.0 - disc, 1e-9);
  EXPECT_EQ(balance.uncovered_area, 0.0);
}

// A uniform absorber of extinction k over a black ground: only sunlight
// crossing the limb leaves. With u = sqrt(R_top^2 - b^2) the chord is 2u and
// (1 / R_top^2) * integral of exp(-2 k u) d(b^2) = (2 / R_top^2) * integral
// over (0, H) of u exp(-2 k u) du, H = sqrt(R_top^2 - R_g^2), which is
// (2 / R_top^2) * (1 - (1 + 2 k H) exp(-2 k H)) / (2 k)^2.
TEST(EnergyBalance, AbsorberOverABlackGroundMatchesTheChordIntegral) {
  Atmosphere a = testing::Earth();
  const double k = 2e-6;
  Constituent absorber;
  absorber.name = "absorber";
  absorber.absorption_per_m = Spectrum(k);
  absorber.density.layers = {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}};
  a.constituents = {absorber};
  a.ground_albedo = Spectrum(0.0);
  const double top = a.top_radius_m, h = std::sqrt(top * top - a.bottom_radius_m * a.bottom_radius_m);
  const double expected = 2.0 / (top * top) * (1.0 - (1.0 + 2.0 * k * h) * std::exp(-2.0 * k * h)) / (4.0 * k * k);
  EnergyBalance balance = ComputeEnergyBalance(Bake(a, StressBakeSettings()));
  // Table interpolation of the optical depth (64 x 16 texels) near the
  // ground-grazing chords, which carry the most optical depth: 1 %.
  EXPECT_NEAR(balance.transmitted.x / expected, 1.0, 0.01);
  EXPECT_EQ(balance.scattered, Spectrum(0.0));
}

// The checker must fire on a corrupted bake.
class InvariantCheckerTest : public ::testing::Test {
 protected:
  void SetUp() override { luts_ = Bake(testing::Earth(), testing::SmallBakeSettings(), &report_); }
  LutSet luts_;
  BakeReport report_;
};

TEST_F(InvariantCheckerTest, CleanBakeHasNoViolations) {
  EXPECT_EQ(CheckTableInvariants(luts_, report_).violations, 0);
  EXPECT_EQ(CheckTwinInvariants(luts_, report_, 20000, kSeed).violations, 0);
}

TEST_F(InvariantCheckerTest, FindsNanNegativeAndOverBrightTexels) {
  luts_.scattering.texels[40] = std::numeric_limits<float>::quiet_NaN();
  luts_.irradiance.texels[4] = -1e-3f;
  luts_.single_mie_scattering.texels[8] = 10.0f * float(luts_.atmosphere.solar_irradiance.x);
  luts_.transmittance.texels[0] = -0.5f;  // optical depth < 0: transmittance > 1
  InvariantReport r = CheckTableInvariants(luts_, report_);
  EXPECT_EQ(r.violations, 4) << Examples(r);
}

TEST_F(InvariantCheckerTest, FindsTwinTransmittanceAboveOneAndRadianceAboveTheBound) {
  for (std::size_t i = 0; i < luts_.transmittance.texels.size(); i += 4) luts_.transmittance.texels[i] = -1.0f;
  EXPECT_GT(CheckTwinInvariants(luts_, report_, 2000, kSeed).violations, 0);
  LutSet bright = Bake(testing::Earth(), testing::SmallBakeSettings(), &report_);
  for (float& v : bright.scattering.texels) v *= 1e4f;
  EXPECT_GT(CheckTwinInvariants(bright, report_, 2000, kSeed).violations, 0);
}

TEST_F(InvariantCheckerTest, FindsTransmittanceThatDependsOnDirection) {
  // Optical depths that grow along a ray break monotonicity and the symmetry
  // of the difference formula: replace them by noise.
  std::uint32_t state = 1;
  for (std::size_t i = 0; i < luts_.transmittance.texels.size(); ++i) {
    state = state * 1664525u + 1013904223u;
    luts_.transmittance.texels[i] = float(state >> 8) / float(1u << 24);
  }
  InvariantReport r = CheckTwinInvariants(luts_, report_, 2000, kSeed);
  EXPECT_GT(r.violations, 0);
  bool direction = false;
  for (const std::string& e : r.examples) direction |= e.find("transmittance") != std::string::npos;
  EXPECT_TRUE(direction) << Examples(r);
}

}  // namespace
}  // namespace skybake
