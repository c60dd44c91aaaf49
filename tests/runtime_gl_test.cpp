// The shipped GLSL snippet (definitions + generated constants + functions):
// glslangValidator accepts it as GLSL ES 3.00 and GLSL 3.30 core, and on a
// real driver (Mesa llvmpipe, EGL surfaceless) it gives the numbers of the
// CPU twin, which compiles the same function bodies in double precision.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/scene.h"
#include "bake/spectral.h"
#include "formats/lut_files.h"
#include "formats/manifest.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/snippet.h"
#include "tests/gl_context.h"
#include "tests/runtime_queries.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

using glsl::vec3;
using testing::GlContext;
using namespace testing;  // RuntimeOutput's names

// A main() that evaluates one query (EvaluateQuery, tests/runtime_queries.h)
// per fragment.
const std::string kMain = std::string(R"(
uniform sampler2D transmittance_texture;
uniform sampler3D scattering_texture;
uniform sampler3D single_mie_scattering_texture;
uniform sampler2D irradiance_texture;
)") + kGlslEvaluateQuery + R"(
void main() {
  skybake_output = vec4(EvaluateQuery(skybake_input(0), skybake_input(1), skybake_input(2), skybake_input(3)), 1.0);
}
)";

std::string FragmentSource(const LutSet& luts, const SnippetParts& parts = {}) {
  return RuntimeSnippetSource(ShadingLanguage::kGlsl, luts.parameters, luts.atmosphere.wavelengths_nm, luts.atmosphere.name, parts) + kMain;
}

// ---- the bake ships the snippet ----

TEST(RuntimeSnippet, BakeWritesItWithConstantsFromTheManifestParameters) {
  testing::TempDir dir;
  const std::filesystem::path lut = dir.path() / "lut";
  std::string err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth -q --pack-mie -o " + testing::ShellQuote(lut) +
                                    " --orders 1 --transmittance-size 32 8 --irradiance-size 8 4"
                                    " --scattering-size 4 8 4 4 --ray-samples 8 --sphere-samples 4",
                                dir, nullptr, &err),
            0)
      << err;
  // The constants are a function of what the manifest records, so they agree
  // with the tables by construction; a loader that rebuilds them gets the same text.
  const LutSet loaded = LoadLutSet(lut);
  const char* const extensions[] = {"glsl", "hlsl", "metal", "wgsl"};
  for (ShadingLanguage language : kShadingLanguages) {
    const std::string ext = extensions[static_cast<int>(language)];
    EXPECT_EQ(testing::ReadText(lut / ("atmosphere_constants." + ext)),
              AtmosphereConstants(language, loaded.parameters, loaded.atmosphere.wavelengths_nm, loaded.atmosphere.name))
        << ext;
  }
  EXPECT_NE(testing::ReadText(lut / "atmosphere_constants.glsl").find("SKYBAKE_HAS_SINGLE_MIE_SCATTERING_TEXTURE 0"),
            std::string::npos);
  EXPECT_NE(testing::ReadText(lut / "atmosphere_constants.wgsl").find("SKYBAKE_HAS_SINGLE_MIE_SCATTERING_TEXTURE = false"),
            std::string::npos);
  const Manifest manifest = ReadManifest(lut);
  std::vector<std::string> listed;
  for (const ManifestFile& f : manifest.shader_files) listed.push_back(f.file);
  EXPECT_EQ(listed, (std::vector<std::string>{"definitions.glsl", "atmosphere_constants.glsl", "functions.glsl",
                                              "definitions.hlsl", "atmosphere_constants.hlsl", "functions.hlsl",
                                              "definitions.metal", "atmosphere_constants.metal", "functions.metal",
                                              "atmosphere_constants.wgsl", "functions.wgsl"}));
  const std::filesystem::path sources = std::filesystem::path(SKYBAKE_SOURCE_DIR) / "shaders_runtime";
  EXPECT_EQ(testing::ReadText(lut / "functions.glsl"),
            testing::ReadText(sources / "primitives.glsl") + testing::ReadText(sources / "phase_functions.glsl") +
                testing::ReadText(sources / "functions.glsl") + testing::ReadText(sources / "aerial_perspective.glsl"));
  // The other languages' definitions and functions are the committed translations.
  for (const char* file : {"definitions.hlsl", "functions.hlsl", "definitions.metal", "functions.metal", "functions.wgsl"}) {
    EXPECT_EQ(testing::ReadText(lut / file), testing::ReadText(sources / "generated" / file)) << file;
  }
}

// --runtime chooses the languages written; none writes no shader.
TEST(RuntimeSnippet, BakeWritesTheLanguagesAskedFor) {
  testing::TempDir dir;
  const std::string bake = testing::Skybake() +
                           " bake earth -q --orders 1 --transmittance-size 32 8 --irradiance-size 8 4"
                           " --scattering-size 4 8 4 4 --ray-samples 8 --sphere-samples 4 --format ktx2 -o ";
  std::string err;
  ASSERT_EQ(testing::RunCommand(bake + testing::ShellQuote(dir.path() / "a") + " --runtime wgsl,hlsl", dir, nullptr, &err), 0)
      << err;
  std::vector<std::string> listed;
  for (const ManifestFile& f : ReadManifest(dir.path() / "a").shader_files) listed.push_back(f.file);
  EXPECT_EQ(listed, (std::vector<std::string>{"atmosphere_constants.wgsl", "functions.wgsl", "definitions.hlsl",
                                              "atmosphere_constants.hlsl", "functions.hlsl"}));
  ASSERT_EQ(testing::RunCommand(bake + testing::ShellQuote(dir.path() / "b") + " --runtime none", dir, nullptr, &err), 0)
      << err;
  EXPECT_TRUE(ReadManifest(dir.path() / "b").shader_files.empty());
  EXPECT_NE(testing::RunCommand(bake + testing::ShellQuote(dir.path() / "c") + " --runtime glsl,spirv", dir, nullptr, &err), 0);
  EXPECT_NE(err.find("--runtime: 'spirv' is not glsl, hlsl, msl, wgsl or none"), std::string::npos) << err;
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "c"));
  EXPECT_NE(testing::RunCommand(bake + testing::ShellQuote(dir.path() / "d") + " --runtime none,glsl", dir, nullptr, &err), 0);
  EXPECT_NE(err.find("--runtime: none cannot be combined with languages"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "d"));
}

// ---- glslangValidator ----

class SnippetValidates : public ::testing::TestWithParam<bool> {};

TEST_P(SnippetValidates, AsGlslEs300AndGlsl330Core) {
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
  const bool pack_mie = GetParam();
  Atmosphere earth = LoadAtmosphere("earth");
  glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, testing::RuntimeTestSettings(pack_mie));
  std::string snippet = RuntimeSnippetSource(ShadingLanguage::kGlsl, p, earth.wavelengths_nm, earth.name);
  // The fragment shader an engine would write: the snippet and a main().
  std::string main_source = std::string("out vec4 skybake_output;\n") + "vec4 skybake_input(int k) { return vec4(float(k)); }\n" +
                            kMain;
  testing::TempDir dir;
  for (const char* version : {"#version 300 es\n", "#version 330 core\n"}) {
    SCOPED_TRACE(version);
    std::filesystem::path file = dir.path() / "sky.frag";
    testing::WriteText(file, version + snippet + main_source);
    std::string out;
    EXPECT_EQ(testing::RunCommand(testing::ShellQuote(SKYBAKE_GLSLANG_VALIDATOR) + " " + testing::ShellQuote(file),
                                  dir, &out),
              0)
        << out;
    // The check can fail: without the generated constants ATMOSPHERE is undefined.
    std::string without_constants = snippet;
    without_constants.erase(without_constants.find("const AtmosphereParameters ATMOSPHERE"));
    testing::WriteText(file, version + without_constants + main_source);
    EXPECT_NE(testing::RunCommand(testing::ShellQuote(SKYBAKE_GLSLANG_VALIDATOR) + " " + testing::ShellQuote(file),
                                  dir, &out),
              0);
  }
}

INSTANTIATE_TEST_SUITE_P(MieTable, SnippetValidates, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "PackedInAlpha" : "Separate"; });

// ---- GLSL on Mesa vs the C++ twin ----

class SnippetOnMesa : public ::testing::TestWithParam<GlContext::Api> {};

// Runs `items` through `source` on the GL context and compares with the
// twin on the same tables.
void ExpectGlMatchesTwin(GlContext* gl, const LutSet& luts, const std::string& source,
                         const std::vector<RuntimeQuery>& items) {
  testing::ExpectMatchesTwin(gl->Description(), luts, items,
                             gl->RunFragmentPass(source, testing::RuntimeQueryInputs(items), 4));
}

// The four tables of `luts` bound to the runtime's samplers.
void SetTables(GlContext* gl, const LutSet& luts) {
  auto set = [&](const char* sampler, const glsl::Texture& t) {
    gl->SetTexture(sampler, t.width, t.height, t.depth, t.texels.data(), t.texels.size());
  };
  set("transmittance_texture", luts.transmittance);
  set("scattering_texture", luts.scattering);
  set("single_mie_scattering_texture", luts.single_mie_scattering);
  set("irradiance_texture", luts.irradiance);
}

TEST_P(SnippetOnMesa, MatchesTheCppTwin) {
  std::string why_not;
  std::unique_ptr<GlContext> gl = GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  static const LutSet luts = Bake(LoadAtmosphere("earth"), testing::RuntimeTestSettings(false));
  SetTables(gl.get(), luts);

  std::vector<testing::RuntimeQuery> items = testing::MakeRuntimeQueries(luts.parameters.bottom_radius, luts.parameters.top_radius);
  ASSERT_GE(items.size(), 1000u);
  ExpectGlMatchesTwin(gl.get(), luts, FragmentSource(luts), items);
}

// A scene's pruned snippet (ground-level daytime: no irradiance functions,
// single Mie packed into alpha, the scattering tables restricted to the
// scene's altitudes and suns) gives the twin's numbers for the functions it
// keeps, at the scene's queries.
TEST_P(SnippetOnMesa, PrunedForASceneMatchesTheCppTwin) {
  std::string why_not;
  std::unique_ptr<GlContext> gl = GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  const Atmosphere earth = LoadAtmosphere("earth");
  const Scene scene = ParseScene(
      "name = \"ground\"\n[effects]\nsky = true\naerial_perspective = { max_distance_km = 30 }\n"
      "[camera]\naltitude_km = [0, 2]\n[objects]\naltitude_km = [0, 2]\n[sun]\nzenith_deg = [0, 90]\n",
      "ground.toml");
  const ScenePlan plan = PlanScene(scene, earth);
  ASSERT_FALSE(plan.irradiance);
  ASSERT_TRUE(plan.pack_single_mie_in_alpha);
  Atmosphere planned = earth;
  BakeSettings settings = testing::RuntimeTestSettings(false);
  ApplyScenePlan(plan, &planned, &settings);
  static const LutSet luts = Bake(planned, settings);
  gl->SetTexture("transmittance_texture", luts.transmittance.width, luts.transmittance.height, 1,
                 luts.transmittance.texels.data(), luts.transmittance.texels.size());
  for (const char* sampler : {"scattering_texture", "single_mie_scattering_texture"}) {
    gl->SetTexture(sampler, luts.scattering.width, luts.scattering.height, luts.scattering.depth,
                   luts.scattering.texels.data(), luts.scattering.texels.size());
  }
  std::vector<testing::RuntimeQuery> items;
  int aerial_items = 0;
  for (const testing::RuntimeQuery& item : testing::MakeRuntimeQueries(luts.parameters.bottom_radius, luts.parameters.top_radius)) {
    const bool irradiance = item.what == kSunIrradiance || item.what == kSkyIrradiance;
    const double altitude = glm::length(item.camera) - luts.parameters.bottom_radius;
    const double sun_zenith_deg = std::acos(glm::dot(glm::normalize(item.camera), item.sun)) * 180.0 / M_PI;
    if (irradiance || altitude > scene.camera_altitude_max_m || sun_zenith_deg > scene.sun_zenith_max_deg) continue;
    // Aerial perspective to objects inside the scene: its short segments
    // read the restricted table only as far as its radii reach.
    const bool aerial = item.what == kAerialRadiance || item.what == kAerialTransmittance ||
                        item.what == kAerialRadianceInShadow;
    if (aerial) {
      const double object_altitude = glm::length(item.extra) - luts.parameters.bottom_radius;
      const double distance = glm::length(item.extra - item.camera);
      if (object_altitude > scene.object_altitude_max_m || distance > scene.effects.aerial_perspective_max_distance_m) {
        continue;
      }
      ++aerial_items;
    }
    items.push_back(item);
  }
  ASSERT_GE(items.size(), 100u);
  ASSERT_GE(aerial_items, 30);
  SnippetParts parts;
  parts.irradiance = false;
  ExpectGlMatchesTwin(gl.get(), luts, FragmentSource(luts, parts), items);
}

// A spectral set's snippet (tables in XYZ, transmittance_is_colour: aerial
// perspective integrates its long segments' optical depth instead of reading
// the table) gives the twin's numbers on every query.
TEST_P(SnippetOnMesa, SpectralSetMatchesTheCppTwin) {
  std::string why_not;
  std::unique_ptr<GlContext> gl = GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  static const LutSet luts =
      BakeSpectral(ReadAtmosphereSource("earth"),
                   MakeSpectralBatches(SpectralWavelengths(6), kDefaultSpectralHigherOrders),
                   testing::RuntimeTestSettings(false));
  ASSERT_EQ(luts.parameters.transmittance_is_colour, 1);
  SetTables(gl.get(), luts);
  SnippetParts parts;
  parts.channels_are_xyz = true;
  ExpectGlMatchesTwin(gl.get(), luts, FragmentSource(luts, parts),
                      testing::MakeRuntimeQueries(luts.parameters.bottom_radius, luts.parameters.top_radius));
}

INSTANTIATE_TEST_SUITE_P(Apis, SnippetOnMesa,
                         ::testing::Values(GlContext::Api::kGles30, GlContext::Api::kDesktop33Core),
                         [](const auto& info) { return info.param == GlContext::Api::kGles30 ? "Gles30" : "Desktop33Core"; });

}  // namespace
}  // namespace skybake
