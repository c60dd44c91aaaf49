// `skybake bench`: the report's format and its errors (no timing assertions;
// speed targets live in docs/benchmark.md, measured by scripts/bench.sh).
#include <gtest/gtest.h>

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace skybake {
namespace {

using testing::RunCommand;
using testing::Skybake;
using testing::TempDir;

const char* kTinyBench =
    " bench earth --transmittance-size 32 8 --irradiance-size 8 4 --scattering-size 4 8 4 2"
    " --ray-samples 8 --sphere-samples 4 --orders 3";

TEST(CliBench, MarkdownListsEveryPhaseTotalAndMemory) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + kTinyBench + " --runs 1", dir, &out, &err), 0) << err;
  for (const char* row : {"| transmittance |", "| single scattering |", "| order 2: scattering density |",
                          "| order 2: indirect irradiance |", "| order 2: multiple scattering |",
                          "| order 3: multiple scattering |", "| write files |", "| **total** |",
                          "peak resident memory:"}) {
    EXPECT_NE(out.find(row), std::string::npos) << row << "\n" << out;
  }
  EXPECT_EQ(out.find("| order 4:"), std::string::npos) << out;
}

TEST(CliBench, JsonHasMediansPerPhaseAndPeakMemory) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + kTinyBench + " --runs 3 --json", dir, &out, &err), 0) << err;
  nlohmann::json j = nlohmann::json::parse(out);
  // transmittance, single scattering, 3 phases per order >= 2, write files.
  ASSERT_EQ(j["phases"].size(), 2u + 3u * 2u + 1u);
  double phase_sum = 0.0;
  for (const auto& phase : j["phases"]) {
    EXPECT_GE(phase["median_seconds"].get<double>(), 0.0) << phase;
    phase_sum += phase["median_seconds"].get<double>();
  }
  ASSERT_EQ(j["total_seconds"].size(), 3u);
  EXPECT_GT(j["median_total_seconds"].get<double>(), 0.0);
  EXPECT_GT(phase_sum, 0.0);
  EXPECT_GT(j["peak_resident_mib"].get<double>(), 1.0);
  EXPECT_TRUE(j["scaling"].empty());
}

// Each scaling configuration's peak memory is its own: a doubled scattering
// axis raises it, and the smaller configurations measured after it (orders 1)
// do not inherit it.
TEST(CliBench, ScalingMeasuresEachConfigurationsOwnPeakMemory) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " bench earth --runs 1 --scaling --json --scattering-size 16 64 16 4 "
                                   "--transmittance-size 64 16 --irradiance-size 16 4 --ray-samples 32",
                       dir, &out, &err),
            0)
      << err;
  const nlohmann::json j = nlohmann::json::parse(out);
  std::map<std::string, double> peak;
  for (const auto& row : j["scaling"]) peak[row["variant"].get<std::string>()] = row["peak_resident_mib"].get<double>();
  const double base = j["peak_resident_mib"].get<double>();
  ASSERT_TRUE(peak.count("scattering r x2") && peak.count("orders 1") && peak.count("threads 1")) << out;
  EXPECT_GT(peak["scattering r x2"], 1.15 * base) << out;
  EXPECT_LT(peak["orders 1"], peak["scattering r x2"]) << out;
  // The wavelength axis bakes what it names.
  std::map<std::string, int> wavelengths;
  for (const auto& row : j["scaling"]) wavelengths[row["variant"].get<std::string>()] = row["wavelengths"].get<int>();
  EXPECT_EQ(j["wavelengths"].get<int>(), 3);
  EXPECT_EQ(wavelengths["wavelengths 3"], 3);
  EXPECT_EQ(wavelengths["wavelengths 15"], 15);
  EXPECT_EQ(wavelengths["wavelengths 45"], 45);
  EXPECT_EQ(wavelengths["orders 1"], 3);
}

TEST(CliBench, Errors) {
  TempDir dir;
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bench earth --runs 0", dir, nullptr, &err), 1);
  EXPECT_NE(err.find("--runs"), std::string::npos) << err;
  EXPECT_EQ(RunCommand(Skybake() + " bench no-such-planet --runs 1", dir, nullptr, &err), 3);  // no such file
  EXPECT_EQ(RunCommand(Skybake() + " bench earth --runs 1 --wavelengths 2", dir, nullptr, &err), 1);  // an option value
  EXPECT_NE(err.find("at least 3 wavelengths"), std::string::npos) << err;
  EXPECT_EQ(RunCommand(Skybake() + " bench earth --scattering-size 4 7 4 2 --runs 1", dir, nullptr, &err), 1);
  EXPECT_NE(err.find("must be even"), std::string::npos) << err;
}

}  // namespace
}  // namespace skybake
