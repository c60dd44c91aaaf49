// The accuracy targets of the default `earth` bake (4 orders, default sizes,
// float), through the command line as a user runs it (`skybake bake` then
// `skybake eval`), against the independent Monte Carlo reference committed
// in reference/cases/ (docs/report.md says how it was made). One test (ctest
// runs each test in its own process) and one default bake: the slowest test
// in the suite, and the one that holds the headline figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "formats/query_csv.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

const std::string kCasesDir = std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/";
const char* const kChannels[] = {"680nm", "550nm", "440nm"};

QueryTable ReadResults(const std::filesystem::path& path) {
  return ParseQueryCsv(testing::ReadText(path), path.filename().string(), ExtraColumns::kKeepAsResults);
}

struct Evaluated {
  QueryTable cases, horizon;
};

// `skybake bake earth BAKE_OPTIONS`, evaluated on the case set and on the
// near-horizon aerial-perspective segments.
Evaluated BakeEarth(const std::string& bake_options) {
  testing::TempDir dir;
  const std::string out = testing::ShellQuote((dir.path() / "earth").string());
  auto eval = [&](const std::string& cases, const std::string& results) {
    return testing::Skybake() + " eval " + out + " --in " + testing::ShellQuote(kCasesDir + cases) + " --out " +
           testing::ShellQuote((dir.path() / results).string());
  };
  std::string err;
  Evaluated e;
  const std::string bake = testing::Skybake() + " bake earth -o " + out + " --format ktx2 -q " + bake_options;
  if (testing::RunCommand(bake, dir, nullptr, &err) ||
      testing::RunCommand(eval("earth.csv", "cases.csv"), dir, nullptr, &err) ||
      testing::RunCommand(eval("earth_aerial_horizon.csv", "horizon.csv"), dir, nullptr, &err)) {
    ADD_FAILURE() << err;
    return e;
  }
  e.cases = ReadResults(dir.path() / "cases.csv");
  e.horizon = ReadResults(dir.path() / "horizon.csv");
  return e;
}

double Value(const QueryTable& table, size_t row, const std::string& column) {
  return table.results[row][table.ResultColumn(column)];
}

// Daylight radiance against the all-orders reference, whose standard error on
// these cases is <= 0.3% (ReportCases.ReferenceCoversTheCasesWithSmallDaylightNoise),
// at most a third of any bound below, so its noise cannot make a test pass or
// fail on its own.
void CheckDaylight(const QueryTable& bake, double rms_bound, double max_bound) {
  const QueryTable reference = ReadResults(kCasesDir + "earth_reference.csv");
  ASSERT_EQ(bake.queries.size(), reference.queries.size());
  double sum_squares = 0.0, worst = 0.0;
  int count = 0;
  for (size_t i = 0; i < reference.queries.size(); ++i) {
    if (reference.groups[i] != "daylight") continue;
    for (const char* c : kChannels) {
      double expected = Value(reference, i, std::string("radiance_") + c);
      double relative = Value(bake, i, std::string("radiance_") + c) / expected - 1.0;
      sum_squares += relative * relative;
      worst = std::max(worst, std::abs(relative));
      ++count;
    }
  }
  ASSERT_EQ(count, 84 * 3);
  double rms = std::sqrt(sum_squares / count);
  std::printf("daylight radiance against the reference: RMS %.2f%%, max %.2f%% (%d values)\n", 100.0 * rms,
              100.0 * worst, count);
  EXPECT_LE(rms, rms_bound);
  EXPECT_LE(worst, max_bound);
}

// Issue targets for aerial perspective near the horizon (segments of 100 m
// to 5 km at view zenith 85-95 degrees): transmittance within 0.1% and
// in-scattered radiance within 5% of the reference (standard errors
// 0.17-0.30%).
void CheckAerialPerspectiveNearTheHorizon(const QueryTable& bake) {
  const QueryTable reference = ReadResults(kCasesDir + "earth_aerial_horizon_reference.csv");
  ASSERT_EQ(bake.queries.size(), reference.queries.size());
  double worst_radiance = 0.0, worst_transmittance = 0.0;
  for (size_t i = 0; i < reference.queries.size(); ++i) {
    for (const char* c : kChannels) {
      double radiance = std::abs(Value(bake, i, std::string("radiance_") + c) /
                                     Value(reference, i, std::string("radiance_") + c) -
                                 1.0);
      double transmittance = std::abs(Value(bake, i, std::string("transmittance_") + c) /
                                          Value(reference, i, std::string("transmittance_") + c) -
                                      1.0);
      EXPECT_LE(radiance, 0.05) << "row " << i << " " << c;
      EXPECT_LE(transmittance, 1e-3) << "row " << i << " " << c;
      worst_radiance = std::max(worst_radiance, radiance);
      worst_transmittance = std::max(worst_transmittance, transmittance);
    }
  }
  std::printf("near-horizon aerial perspective: radiance max %.2f%%, transmittance max %.2g\n",
              100.0 * worst_radiance, worst_transmittance);
}

TEST(EarthAccuracy, DefaultBakeMeetsTheDaylightAndNearHorizonTargets) {
  const Evaluated earth = BakeEarth("");
  ASSERT_FALSE(earth.cases.queries.empty());
  // Issue targets: RMS <= 1%, max <= 3%.
  CheckDaylight(earth.cases, 0.01, 0.03);
  CheckAerialPerspectiveNearTheHorizon(earth.horizon);
}

// The preview bake's target (issue): daylight radiance RMS <= 2%. Its largest
// error (5.4% as measured, docs/benchmark.md) is bounded at 8% so that a
// preview that loses a part of the sky fails.
TEST(EarthAccuracy, PreviewBakeMeetsItsDaylightTarget) {
  const Evaluated earth = BakeEarth("--preview");
  ASSERT_FALSE(earth.cases.queries.empty());
  CheckDaylight(earth.cases, 0.02, 0.08);
}

}  // namespace
}  // namespace skybake
