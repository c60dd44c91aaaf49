// Regression tests for the `info`, `render` and engine-example defects of
// issue 18 ("a newcomer's first hour"), each named after its defect. The
// command-line tests run testing::Skybake() (SKYBAKE_TEST_EXE picks another
// build) on small bakes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "core/constants.h"
#include "formats/lut_files.h"
#include "render/image_files.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

const std::string& kSmallBake = testing::kSmallBakeOptions;

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
  // One stderr line per plot left out names what it needs: the irradiance
  // table, and for the sunset plot suns below the scene's [0, 90] degrees.
  ASSERT_EQ(report["plots_left_out"].size(), 2u) << report["plots_left_out"];
  const std::vector<std::string> lines = Lines(err);
  ASSERT_EQ(lines.size(), 2u) << err;
  EXPECT_NE(lines[0].find("lut_irradiance"), std::string::npos) << err;
  EXPECT_NE(lines[0].find("irradiance table"), std::string::npos) << err;
  EXPECT_NE(lines[1].find("lut_sunset"), std::string::npos) << err;
  EXPECT_NE(lines[1].find("outside the scene's [0, 90]"), std::string::npos) << err;

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
  // 4 views, the contact sheet and 4 plots from render; 4 plots from info.
  EXPECT_EQ(pngs, 4 + 1 + 4 + 4);
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

// The luminance Y = 0.2126 R + 0.7152 G + 0.0722 B of each pixel of a
// linear EXR written by render.
std::vector<double> ExrLuminance(const fs::path& path, int* width, int* height) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) return {};
  const OIIO::ImageSpec& spec = input->spec();
  *width = spec.width;
  *height = spec.height;
  std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
  input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
  std::vector<double> y(std::size_t(spec.width) * spec.height);
  for (std::size_t i = 0; i < y.size(); ++i) {
    const float* p = &pixels[i * spec.nchannels];
    y[i] = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
  }
  return y;
}

// `render` exposes each image automatically by default: the fisheye shows
// only sky, so its exposure is log2(-ln(1 - 0.18) / median Y) over the
// pixels inside its circle (Y > 0), computed here from the EXR; the PNG is
// that exposure's tone mapping, and the EV is reported in --json, on stderr
// and in the PNG. A number still fixes the exposure.
TEST(NewcomerDefects, RenderAutoExposureMapsTheMedianSkyToMidGrey) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images";
  SmallBake(dir, "earth", lut);
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " render " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --views fisheye --size 48 --sun-zenith 30 --json",
                       dir, &out, &err),
            0)
      << err;
  int width = 0, height = 0;
  std::vector<double> y = ExrLuminance(images / "fisheye_sz30.exr", &width, &height);
  ASSERT_EQ(width, 48);
  y.erase(std::remove_if(y.begin(), y.end(), [](double v) { return !(v > 0.0); }), y.end());
  std::sort(y.begin(), y.end());
  // Inside the circle: pi/4 of the square, give or take its rim.
  ASSERT_NEAR(double(y.size()) / (width * height), kPi / 4, 0.03);
  const double expected_ev = std::log2(-std::log(1.0 - 0.18) / y[y.size() / 2]);

  const nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_EQ(report["images"].size(), 1u);
  ASSERT_TRUE(report["images"][0].contains("exposure_ev")) << out;
  const double ev = report["images"][0]["exposure_ev"].get<double>();
  EXPECT_NEAR(ev, expected_ev, 1e-9);
  EXPECT_EQ(report["exposure"], "auto");
  char printed[32];
  std::snprintf(printed, sizeof(printed), "%.4g EV", expected_ev);
  EXPECT_NE(err.find(printed), std::string::npos) << err;

  // The PNG is the EXR tone-mapped at that exposure, and records it.
  const LutSet luts = LoadLutSet(lut);
  const render::ToneMap tone{expected_ev, render::WhiteBalance(luts.parameters.solar_irradiance)};
  render::Image exr;
  exr.width = width, exr.height = height;
  {
    auto input = OIIO::ImageInput::open((images / "fisheye_sz30.exr").string());
    ASSERT_TRUE(input);
    exr.rgb.resize(std::size_t(3) * width * height);
    input->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, exr.rgb.data());
  }
  const render::Rgb8 png = render::ReadPng(images / "fisheye_sz30.png");
  EXPECT_TRUE(png.rgb == render::ToneMapToSrgb(exr, tone).rgb);
  EXPECT_NE(testing::ReadText(images / "fisheye_sz30.png").find(printed), std::string::npos);

  // A fixed exposure is kept as given.
  ASSERT_EQ(RunCommand(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --views fisheye --size 48 --sun-zenith 30 --exposure 1.5 --json",
                       dir, &out, &err),
            0)
      << err;
  EXPECT_EQ(nlohmann::json::parse(out)["images"][0]["exposure_ev"].get<double>(), 1.5);
  EXPECT_TRUE(render::ReadPng(images / "fisheye_sz30.png").rgb ==
              render::ToneMapToSrgb(exr, render::ToneMap{1.5, tone.white}).rgb);
  EXPECT_EQ(RunCommand(Skybake() + " render " + ShellQuote(lut) + " -o " + ShellQuote(images) + " --exposure bright",
                       dir, &out, &err),
            1);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
}

// A dim atmosphere's default render is not black: heavy fog with a low sun,
// where the former fixed exposure left the sky near black.
TEST(NewcomerDefects, RenderDefaultOfADimPresetIsNotBlack) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images";
  SmallBake(dir, "heavy-fog", lut);
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --views fisheye --size 32 --sun-zenith 85",
                       dir, nullptr, &err),
            0)
      << err;
  const render::Rgb8 png = render::ReadPng(images / "fisheye_sz85.png");
  // The median green value of the pixels inside the fisheye's circle: mid-grey
  // 0.18 is 118 in sRGB.
  std::vector<int> green;
  for (int y = 0; y < png.height; ++y)
    for (int x = 0; x < png.width; ++x) {
      double dx = (x + 0.5) / png.width * 2 - 1, dy = (y + 0.5) / png.height * 2 - 1;
      if (dx * dx + dy * dy < 0.9) green.push_back(png.rgb[3 * (std::size_t(y) * png.width + x) + 1]);
    }
  std::sort(green.begin(), green.end());
  EXPECT_GE(green[green.size() / 2], 80) << "median green of the sky";
}

}  // namespace
}  // namespace skybake
