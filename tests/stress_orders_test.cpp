// Scattering orders in a stiff medium: `orders = 0` (auto) with the
// extrapolated geometric tail against a brute-force run of many orders.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

// A 10 km slab of constant density over Earth's radius: vertical optical
// depth 10, single-scattering albedo 0.99, isotropic phase (the moderately
// stiff case of docs/stability.md).
Atmosphere StiffSlab() {
  Atmosphere a = testing::Earth();
  a.name = "stiff-slab";
  a.top_radius_m = a.bottom_radius_m + 10e3;
  Constituent haze;
  haze.name = "haze";
  haze.scattering_per_m = Spectrum(0.99e-3);
  haze.absorption_per_m = Spectrum(0.01e-3);
  haze.phase = PhaseFunction{PhaseKind::kIsotropic, 0.0};
  haze.density.layers = {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}};
  a.constituents = {haze};
  return a;
}

// Reduced tables: the comparison is between two bakes on the same grid.
BakeSettings SmallTables(int orders, bool extrapolate_tail = false) {
  BakeSettings s;
  s.orders = orders;
  s.extrapolate_tail = extrapolate_tail;
  s.transmittance_width = 64;
  s.transmittance_height = 16;
  s.irradiance_width = 16;
  s.irradiance_height = 8;
  s.scattering_r_size = 8;
  s.scattering_mu_size = 16;
  s.scattering_mu_s_size = 8;
  s.scattering_nu_size = 4;
  s.ray_samples = 32;
  s.sphere_samples = 8;
  return s;
}

// Largest relative difference over the texels holding at least 1e-3 of the
// table's largest value (smaller ones are dark twilight texels whose float
// rounding alone exceeds the tolerance).
double MaxRelativeDifference(const glsl::Texture& a, const glsl::Texture& reference) {
  float peak = 0.0f;
  for (std::size_t i = 0; i < reference.texels.size(); ++i) {
    if (i % 4 != 3) peak = std::max(peak, reference.texels[i]);
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < reference.texels.size(); ++i) {
    if (i % 4 == 3 || reference.texels[i] < 1e-3f * peak) continue;
    worst = std::max(worst, std::abs(double(a.texels[i]) - reference.texels[i]) / reference.texels[i]);
  }
  return worst;
}

struct StiffBakes {
  LutSet brute, accelerated, plain;
  BakeReport brute_report, accelerated_report, plain_report;
};

const StiffBakes& Bakes() {
  static const StiffBakes bakes = [] {
    StiffBakes b;
    b.brute = Bake(StiffSlab(), SmallTables(100), &b.brute_report);
    b.accelerated = Bake(StiffSlab(), SmallTables(0), &b.accelerated_report);
    // Plain iteration stopped at the same order, without the tail.
    b.plain = Bake(StiffSlab(), SmallTables(b.accelerated_report.orders_used), &b.plain_report);
    return b;
  }();
  return bakes;
}

TEST(Orders, BruteForceReferenceIsItselfConverged) {
  const BakeReport& r = Bakes().brute_report;
  EXPECT_EQ(r.orders_used, 100);
  EXPECT_GT(r.order_ratio, 0.5) << "the case should be stiff";
  EXPECT_LT(r.order_ratio, 1.0);
  // Its own geometric estimate of the orders past 100, small against the 1%
  // the accelerated bake is held to.
  EXPECT_LT(r.remaining_error, 1e-3);
}

TEST(Orders, AutoWithTailMatchesManyOrdersWithinOnePercentAtAFractionOfTheOrders) {
  const StiffBakes& b = Bakes();
  const BakeReport& r = b.accelerated_report;
  EXPECT_GT(r.extrapolated_tail, 0.0);
  EXPECT_LT(r.remaining_error, 1e-4);
  EXPECT_LE(r.orders_used, 40) << "orders are the bake's cost: a fraction of the 100 of the brute-force run";
  EXPECT_LT(MaxRelativeDifference(b.accelerated.scattering, b.brute.scattering), 0.01);
  EXPECT_LT(MaxRelativeDifference(b.accelerated.irradiance, b.brute.irradiance), 0.01);
  std::printf("orders used %d, ratio %.4f, tail %.3g, estimated remaining %.3g; max relative difference to 100 "
              "orders: scattering %.3g, irradiance %.3g; without the tail: scattering %.3g\n",
              r.orders_used, r.order_ratio, r.extrapolated_tail, r.remaining_error,
              MaxRelativeDifference(b.accelerated.scattering, b.brute.scattering),
              MaxRelativeDifference(b.accelerated.irradiance, b.brute.irradiance),
              MaxRelativeDifference(b.plain.scattering, b.brute.scattering));
}

TEST(Orders, TheTailIsWhatMakesTheDifference) {
  // The same orders without the tail are far from converged: the test above
  // would fail if the extrapolation did nothing.
  const StiffBakes& b = Bakes();
  EXPECT_GT(MaxRelativeDifference(b.plain.scattering, b.brute.scattering), 0.02);
  EXPECT_EQ(b.plain_report.extrapolated_tail, 0.0);
  EXPECT_GT(b.plain_report.remaining_error, 0.02);
}

TEST(Orders, AFixedCountWithTheTailIsCloserToConvergedThanWithout) {
  // Earth at 4 orders against 12 (remaining error < 1e-6): the tail of the
  // orders not computed, extrapolated from the last three, must bring the
  // table closer, and by much (orders decay by 0.1-0.35 per order on Earth).
  BakeReport with_report, without_report;
  LutSet converged = Bake(testing::Earth(), SmallTables(12));
  LutSet with_tail = Bake(testing::Earth(), SmallTables(4, true), &with_report);
  LutSet without_tail = Bake(testing::Earth(), SmallTables(4, false), &without_report);
  double with = MaxRelativeDifference(with_tail.scattering, converged.scattering);
  double without = MaxRelativeDifference(without_tail.scattering, converged.scattering);
  std::printf("4 orders against 12: with the tail %.3g, without %.3g (tail %.3g)\n", with, without,
              with_report.extrapolated_tail);
  EXPECT_GT(with_report.extrapolated_tail, 0.0);
  EXPECT_EQ(without_report.extrapolated_tail, 0.0);
  EXPECT_LT(with, 0.5 * without);
  EXPECT_LT(MaxRelativeDifference(with_tail.irradiance, converged.irradiance),
            MaxRelativeDifference(without_tail.irradiance, converged.irradiance));
}

TEST(Orders, EarthConvergesInAFewOrders) {
  BakeReport report;
  Bake(testing::Earth(), SmallTables(0), &report);
  EXPECT_LT(report.remaining_error, 1e-4);
  EXPECT_LT(report.order_ratio, 0.5);
  EXPECT_LE(report.orders_used, 12);
}

TEST(Orders, NoScatteringStopsAfterTheSecondOrder) {
  Atmosphere a = StiffSlab();
  a.constituents[0].scattering_per_m = Spectrum(0.0);
  a.constituents[0].absorption_per_m = Spectrum(1e-3);
  BakeReport report;
  LutSet luts = Bake(a, SmallTables(0), &report);
  EXPECT_EQ(report.orders_used, 2);
  EXPECT_EQ(report.extrapolated_tail, 0.0);
  for (float v : luts.scattering.texels) EXPECT_EQ(v, 0.0f);
}

TEST(Orders, CommandLineAcceptsAutoAndReportsConvergence) {
  testing::TempDir dir;
  const std::string bake = testing::Skybake() + " bake earth -o " + testing::ShellQuote(dir.path() / "out") +
                           " --transmittance-size 64 16 --irradiance-size 16 8 --scattering-size 8 16 8 4"
                           " --ray-samples 32 --sphere-samples 8 --format exr -q --json";
  std::string out, err;
  ASSERT_EQ(testing::RunCommand(bake + " --orders auto", dir, &out, &err), 0) << err;
  nlohmann::json j = nlohmann::json::parse(out);
  EXPECT_EQ(j["orders"], "auto");
  EXPECT_GE(j["orders_used"].get<int>(), 3);
  EXPECT_LT(j["remaining_error"].get<double>(), j["order_tolerance"].get<double>());
  // The manifest keeps the request and records the orders the tables hold.
  nlohmann::json manifest = nlohmann::json::parse(testing::ReadText(dir.path() / "out" / "skybake.json"));
  EXPECT_EQ(manifest["bake"]["orders"], "auto");
  EXPECT_EQ(manifest["bake"]["orders_used"], j["orders_used"]);
  // One order: nothing to compare, so the remaining error is unknown.
  ASSERT_EQ(testing::RunCommand(bake + " --orders 1", dir, &out, &err), 0) << err;
  EXPECT_TRUE(nlohmann::json::parse(out)["remaining_error"].is_null());
  for (const char* bad : {"many", "4x"}) {  // not a count: usage error
    EXPECT_EQ(testing::RunCommand(bake + " --orders '" + bad + "'", dir, &out, &err), 1) << bad;
    EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  }
  // Out of range: usage errors too, as every bad option value (0 is auto).
  EXPECT_EQ(testing::RunCommand(bake + " --orders -1", dir, &out, &err), 1);
  EXPECT_EQ(testing::RunCommand(bake + " --orders 101", dir, &out, &err), 1);
  EXPECT_EQ(testing::RunCommand(bake + " --orders auto --max-orders 1", dir, &out, &err), 1);
  EXPECT_EQ(testing::RunCommand(bake + " --orders auto --order-tolerance 0", dir, &out, &err), 1);
}

}  // namespace
}  // namespace skybake
