// Regression tests for the `info`, `render` and engine-example defects of
// issue 18 ("a newcomer's first hour"), each named after its defect. The
// command-line tests run testing::Skybake() (SKYBAKE_TEST_EXE picks another
// build) on small bakes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
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

// The chunk types of a PNG file, in file order (empty if it is not a PNG).
std::vector<std::string> PngChunks(const fs::path& path) {
  const std::string bytes = testing::ReadText(path);
  const std::string signature = "\x89PNG\r\n\x1a\n";
  std::vector<std::string> chunks;
  if (bytes.compare(0, signature.size(), signature) != 0) return chunks;
  // Each chunk: 4-byte big-endian data length, 4-byte type, data, 4-byte CRC.
  for (std::size_t at = signature.size(); at + 8 <= bytes.size();) {
    std::size_t length = 0;
    for (int i = 0; i < 4; ++i) length = length << 8 | static_cast<unsigned char>(bytes[at + i]);
    chunks.push_back(bytes.substr(at + 4, 4));
    at += 12 + length;
  }
  return chunks;
}

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

// Every PNG skybake writes (render previews and contact sheet, LUT plots of
// render and info) carries an sRGB chunk ahead of the image data.
TEST(NewcomerDefects, D11_PngsCarrySrgbChunk) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images", plots = dir.path() / "plots";
  SmallBake(dir, "earth", lut);
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --size 16 --sun-zenith 30 --plots",
                       dir, nullptr, &err),
            0)
      << err;
  ASSERT_EQ(RunCommand(Skybake() + " info " + ShellQuote(lut) + " --plot " + ShellQuote(plots), dir, nullptr, &err), 0)
      << err;
  int pngs = 0;
  for (const fs::path& folder : {images, plots}) {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
      if (entry.path().extension() != ".png") continue;
      ++pngs;
      const std::vector<std::string> chunks = PngChunks(entry.path());
      const auto srgb = std::find(chunks.begin(), chunks.end(), "sRGB");
      const auto data = std::find(chunks.begin(), chunks.end(), "IDAT");
      ASSERT_NE(data, chunks.end()) << entry.path();
      EXPECT_TRUE(srgb < data) << entry.path() << ": no sRGB chunk before the image data";
    }
  }
  // 4 views, the contact sheet and 3 plots from render; 3 plots from info.
  EXPECT_EQ(pngs, 4 + 1 + 3 + 3);
}

// On a terminal the render progress bar is redrawn at most
// ProgressBar::kMaxRedrawsPerSecond (10) times a second, not once per row.
TEST(NewcomerDefects, D11_ProgressRedrawThrottled) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "util-linux `script` not installed";
  TempDir dir;
  const fs::path lut = dir.path() / "lut";
  SmallBake(dir, "earth", lut);
  // 2 suns x (128 + 64 + 128 + 32) rows: a redraw per row would be 704.
  const std::string command = Skybake() + " render " + ShellQuote(lut) + " -o " + ShellQuote(dir.path() / "images") +
                              " --size 128 --sun-zenith 30,85";
  std::string out, err;
  // `script` runs the command on a pseudo-terminal and copies what it wrote.
  ASSERT_EQ(RunCommand("script -qec " + ShellQuote(command) + " /dev/null", dir, &out, &err), 0) << err;
  std::size_t redraws = 0;
  for (std::size_t at = out.find("render ["); at != std::string::npos; at = out.find("render [", at + 1)) ++redraws;
  const std::size_t summary = out.find(" images in ");
  ASSERT_NE(summary, std::string::npos) << out;
  const double seconds = std::stod(out.substr(summary + 11));  // printed to 0.1 s
  EXPECT_GE(redraws, 1u) << out;
  EXPECT_LE(redraws, 10.0 * (seconds + 0.1) + 1.0) << seconds << " s; " << out.substr(0, 2000);
}

}  // namespace
}  // namespace skybake
