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
#include "shaders_runtime/twin.h"
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
  std::string joined;
  for (const char* file : {"primitives.glsl", "phase_functions.glsl", "geometry.glsl", "table_mappings.glsl",
                           "shadow_edge.glsl", "lookups.glsl", "sky.glsl", "aerial_perspective.glsl", "per_frame.glsl"}) {
    joined += testing::ReadText(sources / file);
  }
  EXPECT_EQ(testing::ReadText(lut / "functions.glsl"), joined);
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

// The largest relative difference of `gpu` from `twin` over the values that
// exceed 1e-6 of their channel's largest (as ExpectMatchesTwin counts them).
double LargestRelativeDifference(const std::vector<testing::Vec4>& gpu, const std::vector<vec3>& twin) {
  vec3 largest(0.0);
  for (const vec3& v : twin) largest = glm::max(largest, glm::abs(v));
  double worst = 0.0;
  for (std::size_t i = 0; i < twin.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (std::abs(twin[i][c]) <= 1e-6 * largest[c]) continue;
      worst = std::max(worst, std::abs(gpu[i][c] - twin[i][c]) / std::abs(twin[i][c]));
    }
  }
  return worst;
}

// The largest relative differences from the twin's of the radiance and the
// transmittance that `source` writes: its main() writes vec4(OUTPUT, 1.0),
// OUTPUT replaced by `radiance` and by `transmittance`.
std::pair<double, double> RadianceAndTransmittanceDifferences(GlContext* gl, const std::string& source,
                                                              const char* transmittance,
                                                              const std::vector<testing::Vec4>& inputs,
                                                              int inputs_per_item, const std::vector<vec3>& radiances,
                                                              const std::vector<vec3>& transmittances) {
  auto writing = [&](const char* output) {
    std::string s = source;
    s.replace(s.find("OUTPUT"), 6, output);
    return gl->RunFragmentPass(s, inputs, inputs_per_item);
  };
  return {LargestRelativeDifference(writing("radiance"), radiances),
          LargestRelativeDifference(writing(transmittance), transmittances)};
}

// The per-frame tables (per_frame.glsl) built and read on the driver give the
// twin's: the sky view's texels (GetSkyViewRadiance) within the GL test's
// tolerance for the sky radiance they hold (1e-3), the lookups of the twin's
// tables on the driver within 1e-3. The volume's texels hold aerial
// perspective to points beyond the query set's: 49 m segments after sunset,
// where the one cancelling term of short segments (ExpectMatchesTwin) leaves
// 6.6e-2 in float32 on llvmpipe, and ground 40 km away seen at a grazing
// angle, where the table method's transmittance differs by 7.2e-3; the
// tolerances are 1e-1 and 1e-2.
TEST_P(SnippetOnMesa, PerFrameTablesMatchTheCppTwin) {
  std::string why_not;
  std::unique_ptr<GlContext> gl = GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  static const LutSet luts = Bake(LoadAtmosphere("earth"), testing::RuntimeTestSettings(false));
  SetTables(gl.get(), luts);
  const Twin twin(MakeTwinTables(luts));
  const std::string snippet = RuntimeSnippetSource(ShadingLanguage::kGlsl, luts.parameters,
                                                   luts.atmosphere.wavelengths_nm, luts.atmosphere.name);
  const std::string tables = R"(
uniform sampler2D transmittance_texture;
uniform sampler3D scattering_texture;
uniform sampler3D single_mie_scattering_texture;
uniform sampler2D irradiance_texture;
uniform sampler2D sky_view_texture;
uniform sampler3D aerial_perspective_radiance;
uniform sampler3D aerial_perspective_optical_depth;
)";
  auto f = [](double v) { return float(v); };
  auto input = [&](const vec3& v, double w) { return testing::Vec4{f(v.x), f(v.y), f(v.z), f(w)}; };
  const double bottom = luts.parameters.bottom_radius;
  const double degree = M_PI / 180.0;
  for (double sun_zenith : {30.0, 93.0}) {
    const vec3 sun(std::sin(sun_zenith * degree), 0.0, std::cos(sun_zenith * degree));
    const vec3 camera(0.0, 0.0, bottom + 300.0);
    SCOPED_TRACE("sun at " + std::to_string(sun_zenith) + " degrees");

    // The sky view: every texel built on the driver, then the twin's table read there.
    const glsl::Texture sky_view = twin.SkyView(camera, sun);
    std::vector<testing::Vec4> inputs;
    std::vector<vec3> expected;
    for (int y = 0; y < sky_view.height; ++y) {
      for (int x = 0; x < sky_view.width; ++x) {
        inputs.push_back(input(camera, (x + 0.5) / sky_view.width));
        inputs.push_back(input(sun, (y + 0.5) / sky_view.height));
        expected.push_back(vec3(sky_view.Fetch(x, y)));
      }
    }
    std::vector<testing::Vec4> built = gl->RunFragmentPass(snippet + tables + R"(
void main() {
  vec4 a = skybake_input(0), b = skybake_input(1);
  skybake_output = vec4(GetSkyViewRadiance(ATMOSPHERE, scattering_texture, single_mie_scattering_texture, a.xyz,
                                           b.xyz, vec2(a.w, b.w)), 1.0);
}
)", inputs, 2);
    EXPECT_LT(LargestRelativeDifference(built, expected), 1e-3) << "sky view texels";
    gl->SetTexture("sky_view_texture", sky_view.width, sky_view.height, 1, sky_view.texels.data(),
                   sky_view.texels.size());
    inputs.clear();
    expected.clear();
    for (int i = 0; i < 2000; ++i) {
      const double zenith = std::fmod(i * 0.618034, 1.0) * M_PI, azimuth = (i + 0.5) / 2000.0 * 2.0 * M_PI;
      const vec3 ray(std::sin(zenith) * std::cos(azimuth), std::sin(zenith) * std::sin(azimuth), std::cos(zenith));
      inputs.push_back(input(camera, 0.0));
      inputs.push_back(input(vec3(glm::vec3(ray)), 0.0));
      inputs.push_back(input(sun, 0.0));
      expected.push_back(twin.SkyRadianceFromSkyView(sky_view, camera, vec3(glm::vec3(ray)), sun, nullptr));
    }
    std::vector<testing::Vec4> read = gl->RunFragmentPass(snippet + tables + R"(
void main() {
  vec3 transmittance;
  skybake_output = vec4(GetSkyRadianceFromSkyView(ATMOSPHERE, transmittance_texture, sky_view_texture,
                                                  skybake_input(0).xyz, skybake_input(1).xyz, skybake_input(2).xyz,
                                                  transmittance), 1.0);
}
)", inputs, 3);
    EXPECT_LT(LargestRelativeDifference(read, expected), 1e-3) << "sky view lookups";

    // The volume: 8 x 8 froxels of a 90-degree frustum looking at the
    // horizon, every slice.
    const int froxels = 8, slices = glsl::AERIAL_PERSPECTIVE_SLICES;
    glsl::Texture radiance(froxels, froxels, slices), optical_depth(froxels, froxels, slices);
    std::vector<vec3> expected_transmittance;
    std::vector<vec3> rays;
    inputs.clear();
    expected.clear();
    for (int z = 0; z < slices; ++z) {
      for (int y = 0; y < froxels; ++y) {
        for (int x = 0; x < froxels; ++x) {
          const vec3 ray = vec3(glm::vec3(glm::normalize(vec3(1.0, 2.0 * (x + 0.5) / froxels - 1.0,
                                                               2.0 * (y + 0.5) / froxels - 1.0))));
          vec3 depth;
          const vec3 value = twin.AerialPerspectiveVoxel(camera, ray, (z + 0.5) / slices, sun, &depth);
          radiance.Store(x, y, z, glsl::vec4(value, 1.0));
          optical_depth.Store(x, y, z, glsl::vec4(depth, 1.0));
          inputs.push_back(input(camera, (z + 0.5) / slices));
          inputs.push_back(input(ray, 0.0));
          inputs.push_back(input(sun, 0.0));
          expected.push_back(value);
          expected_transmittance.push_back(glm::exp(-depth));
        }
      }
    }
    const std::string voxel = snippet + tables + R"(
void main() {
  vec3 optical_depth;
  vec3 radiance = GetAerialPerspectiveVoxel(ATMOSPHERE, transmittance_texture, scattering_texture,
                                            single_mie_scattering_texture, skybake_input(0).xyz,
                                            skybake_input(1).xyz, skybake_input(0).w, skybake_input(2).xyz,
                                            optical_depth);
  skybake_output = vec4(OUTPUT, 1.0);
}
)";
    const auto [voxel_radiance, voxel_transmittance] = RadianceAndTransmittanceDifferences(
        gl.get(), voxel, "exp(-optical_depth)", inputs, 3, expected, expected_transmittance);
    EXPECT_LT(voxel_radiance, 1e-1) << "volume radiance";
    EXPECT_LT(voxel_transmittance, 1e-2) << "volume transmittance";
    gl->SetTexture("aerial_perspective_radiance", froxels, froxels, slices, radiance.texels.data(),
                   radiance.texels.size());
    gl->SetTexture("aerial_perspective_optical_depth", froxels, froxels, slices, optical_depth.texels.data(),
                   optical_depth.texels.size());
    inputs.clear();
    expected.clear();
    expected_transmittance.clear();
    for (int i = 0; i < 2000; ++i) {
      const glsl::vec2 uv(std::fmod(i * 0.618034, 1.0), (i + 0.5) / 2000.0);
      const double distance = float(20.0 * std::pow(5000.0, std::fmod(i * 0.414214, 1.0)));
      vec3 transmittance;
      expected.push_back(Twin::SkyRadianceToPointFromVolume(radiance, optical_depth, glsl::vec2(glm::vec2(uv)),
                                                            distance, &transmittance));
      expected_transmittance.push_back(transmittance);
      inputs.push_back(testing::Vec4{f(uv.x), f(uv.y), f(distance), 0.0f});
    }
    const std::string lookup = snippet + tables + R"(
void main() {
  vec4 a = skybake_input(0);
  vec3 transmittance;
  vec3 radiance = GetSkyRadianceToPointFromVolume(aerial_perspective_radiance, aerial_perspective_optical_depth,
                                                  a.xy, a.z, transmittance);
  skybake_output = vec4(OUTPUT, 1.0);
}
)";
    const auto [lookup_radiance, lookup_transmittance] = RadianceAndTransmittanceDifferences(
        gl.get(), lookup, "transmittance", inputs, 1, expected, expected_transmittance);
    EXPECT_LT(lookup_radiance, 1e-3) << "volume lookups";
    EXPECT_LT(lookup_transmittance, 1e-3) << "volume lookups' transmittance";
  }
}

INSTANTIATE_TEST_SUITE_P(Apis, SnippetOnMesa,
                         ::testing::Values(GlContext::Api::kGles30, GlContext::Api::kDesktop33Core),
                         [](const auto& info) { return info.param == GlContext::Api::kGles30 ? "Gles30" : "Desktop33Core"; });

}  // namespace
}  // namespace skybake
