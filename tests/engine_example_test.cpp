// The engine examples (examples/engine): on a small bake each renders,
// headless, through OpenGL ES on Mesa or a Vulkan compute shader on lavapipe,
// the fisheye sky and the aerial view that `skybake render` draws through the
// CPU twin, and they agree; on a scene's bake each draws what the pruned
// snippet can.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "bake/config.h"
#include "formats/lut_files.h"
#include "render/image_files.h"
#include "render/views.h"
#include "shaders_runtime/twin.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

#if defined(SKYBAKE_ENGINE_EXAMPLE_EXE) || defined(SKYBAKE_VULKAN_EXAMPLE_EXE)

render::Image ReadExr(const fs::path& path) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) return {};
  const OIIO::ImageSpec& spec = input->spec();
  render::Image image;
  image.width = spec.width;
  image.height = spec.height;
  std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
  input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
  image.rgb.resize(std::size_t(3) * spec.width * spec.height);
  for (std::size_t i = 0; i < std::size_t(spec.width) * spec.height; ++i)
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = pixels[i * spec.nchannels + c];
  return image;
}

const char* const kSmallBake =
    " --orders 2 --transmittance-size 64 16 --irradiance-size 16 4"
    " --scattering-size 8 32 8 4 --ray-samples 32 --sphere-samples 8";

// Checks the example's `view` images in `images` against the twin's
// rendering of the same view with `settings`.
void ExpectViewMatchesTwin(const Twin& twin, render::View view, const render::ViewSettings& settings,
                           const fs::path& images) {
  const std::string name = render::ToString(view);
  SCOPED_TRACE(name);
  // The PNG exists and, with the sun up, is not black (its exposure is a
  // daylight one, EV 3.3: after sunset the ground is dark in it).
  render::Rgb8 png = render::ReadPng(images / (name + ".png"));
  ASSERT_EQ(png.width, settings.width);
  if (settings.sun_zenith_deg < 90.0) {
    EXPECT_GT(*std::max_element(png.rgb.begin(), png.rgb.end()), 100);
  }
  // The linear radiance: finite, and the twin's wherever a pixel is not
  // on the edge of the sun's disc or of the fisheye's circle (where a
  // float rounding can move the pixel centre across the edge).
  render::Image gpu = ReadExr(images / (name + ".exr"));
  render::Image cpu = render::RenderView(twin, view, settings);
  ASSERT_EQ(gpu.width, cpu.width);
  ASSERT_EQ(gpu.height, cpu.height);
  // The sun's disc is the only place brighter than the sky by far.
  std::vector<float> green;
  for (std::size_t i = 1; i < cpu.rgb.size(); i += 3) green.push_back(cpu.rgb[i]);
  std::nth_element(green.begin(), green.begin() + green.size() / 2, green.end());
  const double sun_disc_level = 20.0 * green[green.size() / 2];
  double worst = 0.0;
  int compared = 0;
  for (int y = 0; y < cpu.height; ++y) {
    for (int x = 0; x < cpu.width; ++x) {
      glsl::vec3 expected = cpu.At(x, y), actual = gpu.At(x, y);
      for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(actual[c])) << x << "," << y;
      bool near_edge = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int nx = std::clamp(x + dx, 0, cpu.width - 1), ny = std::clamp(y + dy, 0, cpu.height - 1);
          // Outside the fisheye's circle the twin leaves 0.
          glsl::vec3 n = cpu.At(nx, ny);
          if (n.y > sun_disc_level || n.y == 0.0) near_edge = true;
        }
      if (near_edge) continue;
      for (int c = 0; c < 3; ++c) {
        double relative = std::abs(actual[c] / expected[c] - 1.0);
        worst = std::max(worst, relative);
        ++compared;
        // The GL test's bounds for float32 against the double twin: 1e-3
        // for the sky, 3e-3 for aerial perspective; the ground points of
        // the aerial view add their own float rounding (a radius near
        // 6.4e6 m: a few 1e-3).
        EXPECT_LE(relative, view == render::View::kFisheye ? 1e-3 : 5e-3)
            << "pixel " << x << "," << y << " channel " << c;
      }
    }
  }
  EXPECT_GT(compared, cpu.width * cpu.height);  // most pixels, 3 channels each
  std::cout << name << ": " << compared << " values, max relative difference GPU vs twin " << worst << "\n";
}

// Both views, as the examples are run here (sun azimuth 30 degrees, the
// camera at their default 100 m), against the twin's.
void ExpectViewsMatchTwin(const Twin& twin, const glsl::vec3& ground_albedo, int width, double sun_zenith_deg,
                          const fs::path& images) {
  render::ViewSettings settings;
  settings.width = width;
  settings.sun_zenith_deg = sun_zenith_deg;
  settings.sun_azimuth_deg = 30.0;
  settings.camera_altitude_m = 100.0;
  settings.ground_albedo = ground_albedo;
  for (render::View view : {render::View::kFisheye, render::View::kAerial})
    ExpectViewMatchesTwin(twin, view, settings, images);
}

void ExpectRendersTheViewsOfSkybakeRender(const std::string& example, const char* no_device) {
  testing::TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images";
  std::string err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth -q -o " + testing::ShellQuote(lut) + kSmallBake, dir,
                                nullptr, &err),
            0)
      << err;
  int code = testing::RunCommand(example + " " + testing::ShellQuote(lut) + " " +
                                     testing::ShellQuote(images) + " --size 64 --sun-zenith 60 --sun-azimuth 30",
                                 dir, nullptr, &err);
  if (code == 3 && err.find(no_device) != std::string::npos) GTEST_SKIP() << err;
  ASSERT_EQ(code, 0) << err;

  const LutSet luts = LoadLutSet(lut);
  const Twin twin(MakeTwinTables(luts));
  ExpectViewsMatchTwin(twin, luts.atmosphere.ground_albedo, 64, 60.0, images);
}

// A scene's bake ships a pruned snippet: the ground-level daytime scene has
// no irradiance table and so no GetSunAndSkyIrradiance. The example draws
// the sky as the twin does and the ground lit by the direct sun only: the
// twin's aerial view with an irradiance table of zeros (no sky light).
void ExpectDrawsWhatASceneBakeHolds(const std::string& example, const char* no_device) {
  testing::TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images";
  const std::string scene = std::string(SKYBAKE_SOURCE_DIR) + "/examples/scenes/ground-daytime-game.toml";
  std::string err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth -q -o " + testing::ShellQuote(lut) + kSmallBake +
                                    " --scene " + testing::ShellQuote(scene),
                                dir, nullptr, &err),
            0)
      << err;
  LutSet luts = LoadLutSet(lut);
  ASSERT_TRUE(luts.irradiance.empty());
  int code = testing::RunCommand(example + " " + testing::ShellQuote(lut) + " " +
                                     testing::ShellQuote(images) + " --size 64 --sun-zenith 60 --sun-azimuth 30",
                                 dir, nullptr, &err);
  if (code == 3 && err.find(no_device) != std::string::npos) GTEST_SKIP() << err;
  ASSERT_EQ(code, 0) << err;
  EXPECT_NE(err.find("direct sun only"), std::string::npos) << err;

  luts.irradiance = glsl::Texture(4, 4);  // all zeros: no sky light on the ground
  const Twin twin(MakeTwinTables(luts));
  ExpectViewsMatchTwin(twin, luts.atmosphere.ground_albedo, 64, 60.0, images);
}

void ExpectBadInputIsOneLineAndAnExitCode(const std::string& example) {
  testing::TempDir dir;
  const fs::path images = dir.path() / "images";
  struct Case {
    std::string arguments;
    int code;
  };
  for (const Case& c : {Case{testing::ShellQuote(dir.path() / "none") + " " + testing::ShellQuote(images), 3},
                        Case{"lut " + testing::ShellQuote(images) + " --sun-zenith nan", 1},
                        Case{"lut " + testing::ShellQuote(images) + " --size 2", 1},
                        Case{"lut " + testing::ShellQuote(images) + " --format png", 1}, Case{"", 1}}) {
    SCOPED_TRACE(c.arguments);
    std::string err;
    EXPECT_EQ(testing::RunCommand(example + " " + c.arguments, dir, nullptr, &err), c.code);
    EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
    EXPECT_FALSE(fs::exists(images / "fisheye.png"));
  }
}

// The examples' pictures drawn on another machine's GPU driver
// (scripts/gpu_bundle.sh: its run.sh draws them there from the bundle's
// bake into images/<example>-sun<zenith>/, 128 pixels wide, sun azimuth 30
// degrees, camera at 100 m) are the twin's within the bounds above.
// SKYBAKE_TEST_GPU_BUNDLE names the bundle, with the images unpacked into
// it; skipped without it.
TEST(EngineExample, PicturesDrawnOnAnotherDriverMatchTheTwin) {
  const char* bundle = std::getenv("SKYBAKE_TEST_GPU_BUNDLE");
  if (bundle == nullptr || *bundle == '\0') GTEST_SKIP() << "SKYBAKE_TEST_GPU_BUNDLE is not set";
  const LutSet luts = LoadLutSet(fs::path(bundle) / "lut");
  const Twin twin(MakeTwinTables(luts));
  int drawn = 0;
  for (const char* example : {"engine", "vulkan"}) {
    for (int sun_zenith_deg : {60, 96}) {
      const fs::path images =
          fs::path(bundle) / "images" / (std::string(example) + "-sun" + std::to_string(sun_zenith_deg));
      SCOPED_TRACE(images.string());
      ASSERT_TRUE(fs::exists(images));
      ExpectViewsMatchTwin(twin, luts.atmosphere.ground_albedo, 128, sun_zenith_deg, images);
      ++drawn;
    }
  }
  EXPECT_EQ(drawn, 4);
}

#endif

#ifdef SKYBAKE_ENGINE_EXAMPLE_EXE

// The example under test, quoted for a shell: SKYBAKE_TEST_ENGINE_EXAMPLE_EXE
// points the tests at another build (for example an older one, to see a
// regression test fail there).
std::string EngineExample() {
  const char* other = std::getenv("SKYBAKE_TEST_ENGINE_EXAMPLE_EXE");
  return testing::ShellQuote(other != nullptr && *other != '\0' ? other : SKYBAKE_ENGINE_EXAMPLE_EXE);
}

TEST(EngineExample, RendersTheViewsOfSkybakeRenderOnTheGpu) {
  ExpectRendersTheViewsOfSkybakeRender(EngineExample(), "no headless OpenGL");
}

TEST(NewcomerDefects, D03_EngineExampleLoadsSceneBake) {
  ExpectDrawsWhatASceneBakeHolds(EngineExample(), "no headless OpenGL");
}

TEST(EngineExample, BadInputIsOneLineAndAnExitCodeWithNothingWritten) {
  ExpectBadInputIsOneLineAndAnExitCode(EngineExample());
}


#else

TEST(EngineExample, RendersTheViewsOfSkybakeRenderOnTheGpu) {
  GTEST_SKIP() << "the engine example was not built (no EGL or OpenGL ES 3 headers)";
}

TEST(NewcomerDefects, D03_EngineExampleLoadsSceneBake) {
  GTEST_SKIP() << "the engine example was not built (no EGL or OpenGL ES 3 headers)";
}

#endif

#ifdef SKYBAKE_VULKAN_EXAMPLE_EXE

// The Vulkan example (a compute shader, the snippet compiled to SPIR-V) draws
// the same pictures, on lavapipe here.
TEST(VulkanExample, RendersTheViewsOfSkybakeRenderOnTheGpu) {
  ExpectRendersTheViewsOfSkybakeRender(testing::ShellQuote(SKYBAKE_VULKAN_EXAMPLE_EXE), "no Vulkan device");
}

TEST(VulkanExample, DrawsWhatASceneBakeHolds) {
  ExpectDrawsWhatASceneBakeHolds(testing::ShellQuote(SKYBAKE_VULKAN_EXAMPLE_EXE), "no Vulkan device");
}

TEST(VulkanExample, BadInputIsOneLineAndAnExitCodeWithNothingWritten) {
  ExpectBadInputIsOneLineAndAnExitCode(testing::ShellQuote(SKYBAKE_VULKAN_EXAMPLE_EXE));
}

#else

TEST(VulkanExample, RendersTheViewsOfSkybakeRenderOnTheGpu) {
  GTEST_SKIP() << "the Vulkan example was not built (no Vulkan headers and loader, or no glslangValidator)";
}

#endif

}  // namespace
}  // namespace skybake
