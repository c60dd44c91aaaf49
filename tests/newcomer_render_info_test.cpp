// Regression tests for the `info`, `render` and engine-example defects of
// issue 18 ("a newcomer's first hour"), each named after its defect. The
// command-line tests run testing::Skybake() (SKYBAKE_TEST_EXE picks another
// build) on small bakes.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

// Table sizes and samples of a bake that takes well under a second.
const char* const kSmallBake =
    " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32"
    " --sphere-samples 8 --orders 2";

const std::string kGroundScene = std::string(SKYBAKE_SOURCE_DIR) + "/examples/scenes/ground-daytime-game.toml";

// Bakes `atmosphere` into `lut` with the small settings and `extra` arguments.
void SmallBake(const TempDir& dir, const std::string& atmosphere, const fs::path& lut, const std::string& extra = "") {
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " bake " + atmosphere + " -q -o " + ShellQuote(lut) + kSmallBake + extra, dir,
                       nullptr, &err),
            0)
      << err;
}

// The ground-level daytime scene leaves the irradiance table out: `info
// --plot` draws the two plots its tables hold and names the third on stderr
// (it used to crash sampling the missing table).
TEST(NewcomerDefects, D01_InfoPlotOnSceneBakeWithoutIrradiance) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", plots = dir.path() / "plots";
  SmallBake(dir, "earth", lut, " --scene " + ShellQuote(kGroundScene));
  ASSERT_FALSE(fs::exists(lut / "irradiance.ktx2"));
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(lut) + " --plot " + ShellQuote(plots), dir, &out, &err),
            0)
      << err;
  const nlohmann::json report = nlohmann::json::parse(out);
  std::vector<std::string> written;
  for (const auto& f : report["plots"]) written.push_back(fs::path(f.get<std::string>()).filename().string());
  std::sort(written.begin(), written.end());
  EXPECT_EQ(written, (std::vector<std::string>{"lut_sky_radiance.png", "lut_sky_radiance.svg",
                                               "lut_transmittance.png", "lut_transmittance.svg"}));
  for (const std::string& f : written) EXPECT_GT(fs::file_size(plots / f), 0u) << f;
  EXPECT_FALSE(fs::exists(plots / "lut_irradiance.svg"));
  // One stderr line names the plot left out and the table it needs.
  ASSERT_EQ(report["plots_left_out"].size(), 1u) << report["plots_left_out"];
  const std::vector<std::string> lines = Lines(err);
  ASSERT_EQ(lines.size(), 1u) << err;
  EXPECT_NE(lines[0].find("lut_irradiance"), std::string::npos) << err;
  EXPECT_NE(lines[0].find("irradiance table"), std::string::npos) << err;

  // `render --plots` on the same set writes the same plots.
  const fs::path images = dir.path() / "images";
  ASSERT_EQ(RunCommand(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --views fisheye --size 16 --sun-zenith 30 --plots",
                       dir, nullptr, &err),
            0)
      << err;
  for (const std::string& f : written) EXPECT_TRUE(fs::exists(images / f)) << f;
  EXPECT_FALSE(fs::exists(images / "lut_irradiance.svg"));
  EXPECT_NE(err.find("lut_irradiance"), std::string::npos) << err;
}

// Stale earth KTX2 files beside a mars set baked as EXR only: `info DIR`
// names them in one warning line and in --json ("unlisted_files"), and
// exits 0 (a warning, as --help states).
TEST(NewcomerDefects, D04_InfoNamesUnlistedFiles) {
  TempDir dir;
  const fs::path earth = dir.path() / "earth", mars = dir.path() / "mars";
  SmallBake(dir, "earth", earth);
  SmallBake(dir, "mars", mars, " --format exr");
  std::vector<std::string> stale;
  for (const fs::directory_entry& entry : fs::directory_iterator(earth)) {
    if (entry.path().extension() != ".ktx2") continue;
    ASSERT_FALSE(fs::exists(mars / entry.path().filename()));
    fs::copy_file(entry.path(), mars / entry.path().filename());
    stale.push_back(entry.path().filename().string());
  }
  std::sort(stale.begin(), stale.end());
  ASSERT_EQ(stale.size(), 4u);

  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " info " + ShellQuote(mars), dir, &out, &err), 0) << err;
  std::vector<std::string> naming;
  for (const std::string& line : Lines(out))
    if (std::all_of(stale.begin(), stale.end(), [&](const std::string& f) { return line.find(f) != std::string::npos; }))
      naming.push_back(line);
  ASSERT_EQ(naming.size(), 1u) << out;
  EXPECT_NE(naming[0].find("not listed in the manifest"), std::string::npos) << naming[0];

  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(mars), dir, &out, &err), 0) << err;
  const nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_TRUE(report.contains("unlisted_files")) << out.substr(0, 400);
  EXPECT_EQ(report["unlisted_files"].get<std::vector<std::string>>(), stale);

  // A set alone in its folder has none, and --help states the exit code.
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(earth), dir, &out, &err), 0) << err;
  EXPECT_TRUE(nlohmann::json::parse(out)["unlisted_files"].empty());
  ASSERT_EQ(RunCommand(Skybake() + " info --help", dir, &out, &err), 0);
  EXPECT_NE(out.find("not list"), std::string::npos) << out;
  EXPECT_NE(out.find("exit 0"), std::string::npos) << out;
}

}  // namespace
}  // namespace skybake
