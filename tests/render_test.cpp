// Preview renders (render/): image sizes, a golden image, the physics the
// pictures must show (sun side brighter, zenith bluer), and the command's
// output discipline (no progress bar unless stderr is a terminal).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "render/image_files.h"
#include "render/views.h"
#include "shaders_runtime/twin.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using glsl::vec3;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

// The tiny tables of the CLI tests: enough for the shape of the sky, fast.
BakeSettings TinySettings() {
  BakeSettings s;
  s.transmittance_width = 64;
  s.transmittance_height = 16;
  s.irradiance_width = 16;
  s.irradiance_height = 4;
  s.scattering_r_size = 8;
  s.scattering_mu_size = 32;
  s.scattering_mu_s_size = 8;
  s.scattering_nu_size = 4;
  s.ray_samples = 32;
  s.sphere_samples = 8;
  s.orders = 2;
  return s;
}
const char* kSmallBake =
    " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32"
    " --sphere-samples 8 --orders 2";

// The `earth` preset baked with the tiny settings, once per test process.
const LutSet& TinyEarth() {
  static const LutSet luts = Bake(LoadAtmosphere("earth"), TinySettings());
  return luts;
}

struct TinyTwin {
  TwinTables tables = MakeTwinTables(TinyEarth());
  Twin twin{tables};
};

render::Image Render(render::View view, int width, double sun_zenith_deg) {
  TinyTwin t;
  render::ViewSettings settings;
  settings.width = width;
  settings.sun_zenith_deg = sun_zenith_deg;
  settings.ground_albedo = TinyEarth().atmosphere.ground_albedo;
  return render::RenderView(t.twin, view, settings);
}

// The fisheye pixel for a view direction (render/views.h: seen from below,
// image up is azimuth 90, image right is azimuth 180; equidistant in zenith).
vec3 FisheyeAt(const render::Image& image, double view_zenith_deg, double azimuth_deg) {
  double rho = view_zenith_deg / 90.0, half = image.width / 2.0, az = azimuth_deg * glsl::PI / 180.0;
  int x = static_cast<int>(std::floor(half - rho * std::cos(az) * half));
  int y = static_cast<int>(std::floor(half - rho * std::sin(az) * half));
  return image.At(std::clamp(x, 0, image.width - 1), std::clamp(y, 0, image.height - 1));
}

TEST(Render, ViewsHaveTheirSizesAndFiniteNonNegativePixels) {
  const struct {
    render::View view;
    int height;
  } cases[] = {{render::View::kFisheye, 40}, {render::View::kPanorama, 20}, {render::View::kSpace, 40},
               {render::View::kAerial, 10}};
  for (const auto& c : cases) {
    render::Image image = Render(c.view, 40, 60.0);
    EXPECT_EQ(image.width, 40) << render::ToString(c.view);
    EXPECT_EQ(image.height, c.height) << render::ToString(c.view);
    ASSERT_EQ(image.rgb.size(), 3u * 40 * c.height);
    for (float v : image.rgb) ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << render::ToString(c.view);
  }
}

TEST(Render, SpaceViewShowsALitPlanetOnBlackSpace) {
  render::Image image = Render(render::View::kSpace, 64, 30.0);
  vec3 corner = image.At(0, 0), centre = image.At(32, 32);
  EXPECT_EQ(corner, vec3(0.0));  // beyond the atmosphere: nothing scatters
  EXPECT_GT(centre.y, 0.0);
}

TEST(Render, SunSideOfTheSkyIsBrighterThanTheAntiSunSideAtLowSun) {
  // Sun 5 degrees above the horizon at azimuth 0. Low in the sky on the sun's
  // side the view is within 20 degrees of the sun, where Mie's forward peak
  // (Cornette-Shanks, g = 0.8) dominates; the anti-sun side sees only the back
  // lobe. Higher up (view zenith 45-60) the two sides differ by only 5-20%
  // (Rayleigh's phase is symmetric), so the pointwise check stays low, and the
  // whole sun-side half of the sky is compared with the anti-sun half.
  render::Image image = Render(render::View::kFisheye, 64, 85.0);
  for (double zenith : {75.0, 80.0, 85.0}) {
    vec3 sun_side = FisheyeAt(image, zenith, 0.0), anti_sun = FisheyeAt(image, zenith, 180.0);
    double ratio = (sun_side.x + sun_side.y + sun_side.z) / (anti_sun.x + anti_sun.y + anti_sun.z);
    EXPECT_GT(ratio, 1.5) << "view zenith " << zenith;
  }
  // Halves: azimuth 0 is the image's left half (render/views.h).
  double left = 0.0, right = 0.0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      vec3 v = image.At(x, y);
      (x < image.width / 2 ? left : right) += v.x + v.y + v.z;
    }
  EXPECT_GT(left, 1.2 * right) << left / right;
}

TEST(Render, ZenithIsBluerThanTheHorizonAtNoonOnEarth) {
  // Rayleigh scattering (lambda^-4) dominates the thin zenith path; toward the
  // horizon the long path extinguishes blue and Mie adds grey, so the
  // blue/red ratio falls. Sun zenith 20 degrees; horizon sample 85 degrees from
  // the zenith, 90 degrees in azimuth from the sun.
  render::Image image = Render(render::View::kFisheye, 64, 20.0);
  vec3 zenith = image.At(32, 32), horizon = FisheyeAt(image, 85.0, 90.0);
  double zenith_ratio = zenith.z / zenith.x, horizon_ratio = horizon.z / horizon.x;
  EXPECT_GT(zenith_ratio, 1.3 * horizon_ratio) << zenith_ratio << " vs " << horizon_ratio;
}

// Golden image: the tiny `earth` tables, a 32-pixel fisheye at sun zenith 60,
// tone-mapped with the default exposure. Tolerance: at most 3 codes (of 255)
// in any channel and 0.5 on average. The same source gives the same floats up
// to libm and compiler differences (~1e-6 relative), so this allows for 8-bit
// rounding flips plus a real margin; a change of the sun zenith by 2 degrees
// exceeds it (checked below), so the test notices a change in the physics,
// the parameterization or the tone curve.
// To update after an intended change:
//   SKYBAKE_UPDATE_GOLDEN=1 ctest --test-dir build -R Render.MatchesGolden
const fs::path kGolden = fs::path(SKYBAKE_SOURCE_DIR) / "tests/data/golden/fisheye_earth_sz60_32.png";

struct Difference {
  int max = 0;
  double mean = 0.0;
};
Difference Compare(const render::Rgb8& a, const render::Rgb8& b) {
  Difference d;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    int delta = std::abs(int(a.rgb[i]) - int(b.rgb[i]));
    d.max = std::max(d.max, delta);
    d.mean += delta;
  }
  d.mean /= static_cast<double>(a.rgb.size());
  return d;
}

render::Rgb8 GoldenCandidate(double sun_zenith_deg) {
  render::ToneMap tone;
  tone.white = render::WhiteBalance(TinyEarth().parameters.solar_irradiance);
  return render::ToneMapToSrgb(Render(render::View::kFisheye, 32, sun_zenith_deg), tone);
}

TEST(Render, MatchesGolden) {
  render::Rgb8 image = GoldenCandidate(60.0);
  const char* update = std::getenv("SKYBAKE_UPDATE_GOLDEN");
  if (update && std::string(update) == "1") {
    StagedFiles staged;
    render::WritePng(staged, kGolden, image, {});
    staged.Commit();
    GTEST_SKIP() << "golden image rewritten: " << kGolden;
  }
  render::Rgb8 golden = render::ReadPng(kGolden);
  ASSERT_EQ(golden.width, image.width);
  ASSERT_EQ(golden.height, image.height);
  Difference d = Compare(image, golden);
  EXPECT_LE(d.max, 3);
  EXPECT_LE(d.mean, 0.5);

  // The tolerance is tight enough to see a 2-degree change of the sun.
  Difference moved = Compare(GoldenCandidate(62.0), golden);
  EXPECT_TRUE(moved.max > 3 || moved.mean > 0.5) << moved.max << " " << moved.mean;
}

// The tone map's sRGB encoding against OpenImageIO's colour management, an
// independent implementation of the same standard, over the whole 0-1 range
// (both in float at least: within 1e-5).
TEST(Render, SrgbEncodingMatchesOpenImageIO) {
  const int n = 4097;
  std::vector<float> linear(3 * n);
  for (int i = 0; i < 3 * n; ++i) linear[i] = float(i / 3) / float(n - 1);
  OIIO::ImageBuf in(OIIO::ImageSpec(n, 1, 3, OIIO::TypeDesc::FLOAT), linear.data()), out;
  ASSERT_TRUE(OIIO::ImageBufAlgo::colorconvert(out, in, "linear", "sRGB")) << out.geterror();
  std::vector<float> encoded(3 * n);
  out.get_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, encoded.data());
  double worst = 0.0;
  for (int i = 0; i < 3 * n; ++i) worst = std::max(worst, std::abs(render::SrgbEncode(linear[i]) - encoded[i]));
  EXPECT_LT(worst, 1e-5);
  // The two branches meet at the breakpoint (continuity of the standard).
  EXPECT_NEAR(render::SrgbEncode(0.0031308), 12.92 * 0.0031308, 1e-6);
  EXPECT_DOUBLE_EQ(render::SrgbEncode(1.0), 1.0);
}

// A bake writes no image, so it must not load OpenImageIO's libraries (about
// half a second per command); the image module loads them when an image is
// written. The dynamic loader's own trace says which files were opened.
TEST(RenderCli, OnlyCommandsThatWriteImagesLoadOpenImageIO) {
  TempDir dir;
  std::string out, err;
  fs::path lut = dir.path() / "earth";
  ASSERT_EQ(RunCommand("LD_DEBUG=files " + Skybake() + " bake earth --quiet -o " + ShellQuote(lut) + kSmallBake,
                       dir, &out, &err),
            0)
      << err;
  EXPECT_NE(err.find("libtbb"), std::string::npos) << "no loader trace";
  EXPECT_EQ(err.find("libOpenImageIO"), std::string::npos);
  ASSERT_EQ(RunCommand("LD_DEBUG=files " + Skybake() + " info " + ShellQuote(lut) + " --plot " +
                           ShellQuote(dir.path() / "plots"),
                       dir, &out, &err),
            0)
      << err;
  EXPECT_NE(err.find("libskybake_images.so"), std::string::npos);
  EXPECT_NE(err.find("libOpenImageIO"), std::string::npos);
  EXPECT_GT(render::ReadPng(dir.path() / "plots" / "lut_transmittance.png").width, 0);
}

// The command end to end: sizes of every output, the JSON report on stdout,
// and the progress bar only on a terminal.
TEST(RenderCli, WritesRequestedSizesAndNoProgressWhenNotATerminal) {
  TempDir dir;
  std::string out, err;
  fs::path lut = dir.path() / "earth", images = dir.path() / "images";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth --quiet -o " + ShellQuote(lut) + kSmallBake, dir, &out, &err), 0)
      << err;
  ASSERT_EQ(RunCommand(Skybake() + " render " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --size 24 --sun-zenith 30,85 --plots --json",
                       dir, &out, &err),
            0)
      << err;
  // stderr is a file here: a one-line summary, no bar (no carriage returns).
  EXPECT_EQ(err.find('\r'), std::string::npos) << err;
  EXPECT_EQ(err.find("[#"), std::string::npos) << err;
  nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_EQ(report["images"].size(), 8u);
  const std::map<std::string, int> heights = {{"fisheye", 24}, {"panorama", 12}, {"space", 24}, {"aerial", 6}};
  for (const auto& entry : report["images"]) {
    render::Rgb8 png = render::ReadPng(entry["png"].get<std::string>());
    EXPECT_EQ(png.width, 24) << entry["png"];
    EXPECT_EQ(png.height, heights.at(entry["view"])) << entry["png"];
    EXPECT_TRUE(fs::exists(entry["exr"].get<std::string>()));
  }
  for (const char* file : {"fisheye_sz30.png", "fisheye_sz85.exr", "aerial_sz85.png", "contact_sheet.png",
                           "lut_transmittance.svg", "lut_sky_radiance.png", "lut_irradiance.png"})
    EXPECT_TRUE(fs::exists(images / file)) << file;
  render::Rgb8 sheet = render::ReadPng(images / "contact_sheet.png");
  EXPECT_GT(sheet.width, 2 * 24);  // two columns side by side
}

TEST(RenderCli, ProgressBarOnlyOnATerminalAndNotWithQuiet) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "util-linux `script` not installed";
  TempDir dir;
  std::string out, err;
  fs::path lut = dir.path() / "earth";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth --quiet -o " + ShellQuote(lut) + kSmallBake, dir, &out, &err), 0)
      << err;
  // `script` runs the command on a pseudo-terminal and copies what it wrote.
  auto on_terminal = [&](const std::string& extra) {
    std::string command = Skybake() + " render " + ShellQuote(lut) + " -o " + ShellQuote(dir.path() / "images") +
                          " --size 16 --views fisheye" + extra;
    EXPECT_EQ(RunCommand("script -qec " + ShellQuote(command) + " /dev/null", dir, &out, &err), 0) << err;
    return out;
  };
  std::string shown = on_terminal("");
  EXPECT_NE(shown.find("render ["), std::string::npos) << shown;
  EXPECT_NE(shown.find('\r'), std::string::npos);
  std::string quiet = on_terminal(" --quiet");
  EXPECT_EQ(quiet.find("render ["), std::string::npos) << quiet;
}

}  // namespace
}  // namespace skybake
