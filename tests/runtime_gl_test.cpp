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
#include "formats/lut_files.h"
#include "formats/manifest.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/snippet.h"
#include "tests/gl_context.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

using glsl::vec3;
using testing::GlContext;

BakeSettings SmallSettings(bool pack_mie) {
  // The comparison is between two evaluations of the same tables, so small
  // tables (fast to bake) test it as well as full ones.
  BakeSettings s = testing::SmallBakeSettings();
  s.pack_single_mie_in_alpha = pack_mie;
  return s;
}

// What one evaluation returns; the same switch is written in GLSL below.
enum Output {
  kSkyRadiance,
  kSkyTransmittance,
  kAerialRadiance,
  kAerialTransmittance,
  kSunIrradiance,
  kSkyIrradiance,
  kTransmittanceToSun,
  kSolarRadiance,
  kAerialRadianceInShadow,
  kOutputCount
};
const char* const kOutputNames[] = {"sky radiance",       "sky transmittance", "aerial radiance",
                                    "aerial transmittance", "sun irradiance",   "sky irradiance",
                                    "transmittance to sun", "solar radiance",   "aerial radiance in shadow"};

// A main() that calls the snippet's entry points. Inputs per item: camera +
// output, view ray, sun direction + shadow length, point (aerial) or normal
// (irradiance).
const char* const kMain = R"(
uniform sampler2D transmittance_texture;
uniform sampler3D scattering_texture;
uniform sampler3D single_mie_scattering_texture;
uniform sampler2D irradiance_texture;
void main() {
  vec4 a = skybake_input(0);
  vec3 camera = a.xyz, view = skybake_input(1).xyz, sun = skybake_input(2).xyz, extra = skybake_input(3).xyz;
  float shadow_length = skybake_input(2).w;
  int what = int(a.w);
  vec3 t, sky, v = vec3(0.0);
  // A scene's snippet lacks the functions of the tables it left out.
  if (what <= 1) {
#if SKYBAKE_HAS_SCATTERING_TEXTURE
    v = GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                       camera, view, sun, t);
    if (what == 1) v = t;
#endif
  } else if (what <= 3) {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
    v = GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture,
                              single_mie_scattering_texture, camera, extra, sun, t);
    if (what == 3) v = t;
#endif
  } else if (what <= 5) {
#if SKYBAKE_HAS_IRRADIANCE_TEXTURE
    v = GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, camera, extra, sun, sky);
    if (what == 5) v = sky;
#endif
  } else if (what == 6) {
    v = GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, length(camera), dot(camera, sun) / length(camera));
  } else if (what == 7) {
    v = GetSolarRadiance(ATMOSPHERE);
  } else {
#if SKYBAKE_HAS_AERIAL_PERSPECTIVE
    v = GetSkyRadianceToPointWithShadow(ATMOSPHERE, transmittance_texture, scattering_texture,
                                        single_mie_scattering_texture, camera, extra, shadow_length, sun, t);
#endif
  }
  skybake_output = vec4(v, 1.0);
}
)";

struct Item {
  int what;
  const char* group;
  vec3 camera, view, sun, extra;  // already rounded to float, as the GPU sees them
  float shadow_length = 0.0f;
};

vec3 ToFloat(const vec3& v) { return vec3(float(v.x), float(v.y), float(v.z)); }

vec3 EvaluateTwin(const LutSet& luts, const Item& item) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  glsl::sampler2D transmittance{&luts.transmittance}, irradiance{&luts.irradiance};
  glsl::sampler3D scattering{&luts.scattering};
  glsl::sampler3D single_mie{luts.single_mie_scattering.empty() ? &luts.scattering : &luts.single_mie_scattering};
  vec3 t, sky, v;
  switch (item.what) {
    case kSkyRadiance:
    case kSkyTransmittance:
      v = glsl::GetSkyRadiance(p, transmittance, scattering, single_mie, item.camera, item.view, item.sun, t);
      return item.what == kSkyRadiance ? v : t;
    case kAerialRadiance:
    case kAerialTransmittance:
      v = glsl::GetSkyRadianceToPoint(p, transmittance, scattering, single_mie, item.camera, item.extra, item.sun, t);
      return item.what == kAerialRadiance ? v : t;
    case kSunIrradiance:
    case kSkyIrradiance:
      v = glsl::GetSunAndSkyIrradiance(p, transmittance, irradiance, item.camera, item.extra, item.sun, sky);
      return item.what == kSunIrradiance ? v : sky;
    case kTransmittanceToSun: {
      double r = glm::length(item.camera);
      return glsl::GetTransmittanceToSun(p, transmittance, r, glm::dot(item.camera, item.sun) / r);
    }
    case kAerialRadianceInShadow:
      return glsl::GetSkyRadianceToPointWithShadow(p, transmittance, scattering, single_mie, item.camera, item.extra,
                                                   item.shadow_length, item.sun, t);
    default:
      return glsl::GetSolarRadiance(p);
  }
}

// Queries in the eval geometry (shaders_runtime/query.h: camera on the z
// axis, so its distance to the centre is exact in float) for every case group.
std::vector<Item> MakeItems(double bottom_radius, double top_radius) {
  std::mt19937 rng(20261123);
  auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  // Items added later draw from their own generator, so the earlier ones stay as they were.
  std::mt19937 more_rng(20261124);
  auto more_uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(more_rng); };
  std::vector<Item> items;
  auto add = [&](const char* group, const Query& q, std::initializer_list<int> outputs, float shadow_length = 0.0f) {
    QueryGeometry g = MakeQueryGeometry(q, bottom_radius);
    vec3 extra = q.has_normal ? g.normal : g.camera + g.view * q.distance_m;
    for (int what : outputs) {
      items.push_back({what, group, ToFloat(g.camera), ToFloat(glm::normalize(ToFloat(g.view))),
                       ToFloat(glm::normalize(ToFloat(g.sun))), ToFloat(extra), shadow_length});
    }
  };
  // The ground at altitude h is seen at view zenith 90 + acos(R / (R + h)).
  auto horizon_deg = [&](double h) { return 90.0 + std::acos(bottom_radius / (bottom_radius + h)) * 180.0 / M_PI; };
  for (int i = 0; i < 150; ++i) {
    Query q;
    q.altitude_m = std::round(uniform(10.0, 20000.0));
    q.sun_zenith_deg = uniform(0.0, 85.0);
    q.view_sun_azimuth_deg = uniform(0.0, 180.0);
    q.view_zenith_deg = uniform(0.0, 180.0);
    if (std::abs(q.view_zenith_deg - horizon_deg(q.altitude_m)) < 0.5) continue;  // the horizon group's
    add("daylight", q, {kSkyRadiance, kSkyTransmittance});
    q.sun_zenith_deg = uniform(90.0, 102.0);
    add("twilight", q, {kSkyRadiance, kSkyTransmittance});
    q.altitude_m = std::round(uniform(top_radius - bottom_radius + 1000.0, 1e6));
    q.view_zenith_deg = uniform(horizon_deg(q.altitude_m) - 30.0, 180.0);
    add("space", q, {kSkyRadiance, kSkyTransmittance});
  }
  for (int i = 0; i < 100; ++i) {
    Query q;
    q.altitude_m = std::round(uniform(10.0, 5000.0));
    q.sun_zenith_deg = uniform(0.0, 100.0);
    q.view_sun_azimuth_deg = uniform(0.0, 180.0);
    double h = horizon_deg(q.altitude_m);
    q.view_zenith_deg = h + (i % 2 ? 1.0 : -1.0) * uniform(0.05, 2.0);
    add("horizon", q, {kSkyRadiance, kSkyTransmittance});
    q.view_zenith_deg = uniform(60.0, h - 0.05);
    q.distance_m = std::exp(uniform(std::log(100.0), std::log(30000.0)));
    add("aerial perspective", q, {kAerialRadiance, kAerialTransmittance});
    add("aerial perspective", q, {kAerialRadianceInShadow}, float(q.distance_m * more_uniform(0.1, 0.9)));
    // A point on the ground, as an engine's terrain gives it.
    Query saved = q;
    q.view_zenith_deg = more_uniform(h + 0.5, 180.0);
    double mu = std::cos(q.view_zenith_deg * M_PI / 180.0), r = bottom_radius + q.altitude_m;
    q.distance_m = -r * mu - std::sqrt(r * r * mu * mu - q.altitude_m * (2.0 * bottom_radius + q.altitude_m));
    add("aerial perspective to the ground", q, {kAerialRadiance, kAerialTransmittance});
    q = saved;
    q.distance_m = 0.0;
    q.has_normal = true;
    q.normal_zenith_deg = uniform(0.0, 90.0);
    q.sun_zenith_deg = uniform(0.0, 95.0);
    add("irradiance", q, {kSunIrradiance, kSkyIrradiance, kTransmittanceToSun});
  }
  add("irradiance", Query{}, {kSolarRadiance});
  return items;
}

std::string FragmentSource(const LutSet& luts, const SnippetParts& parts = {}) {
  return RuntimeSnippetSource(luts.parameters, luts.atmosphere.wavelengths_nm, luts.atmosphere.name, parts) + kMain;
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
  EXPECT_EQ(testing::ReadText(lut / "atmosphere_constants.glsl"),
            AtmosphereConstantsGlsl(loaded.parameters, loaded.atmosphere.wavelengths_nm, loaded.atmosphere.name));
  EXPECT_NE(testing::ReadText(lut / "atmosphere_constants.glsl").find("SKYBAKE_HAS_SINGLE_MIE_SCATTERING_TEXTURE 0"),
            std::string::npos);
  const Manifest manifest = ReadManifest(lut);
  std::vector<std::string> listed;
  for (const ManifestFile& f : manifest.shader_files) listed.push_back(f.file);
  EXPECT_EQ(listed, (std::vector<std::string>{"definitions.glsl", "atmosphere_constants.glsl", "functions.glsl"}));
  const std::filesystem::path sources = std::filesystem::path(SKYBAKE_SOURCE_DIR) / "shaders_runtime";
  EXPECT_EQ(testing::ReadText(lut / "functions.glsl"),
            testing::ReadText(sources / "primitives.glsl") + testing::ReadText(sources / "phase_functions.glsl") +
                testing::ReadText(sources / "functions.glsl") + testing::ReadText(sources / "aerial_perspective.glsl"));
}

// ---- glslangValidator ----

class SnippetValidates : public ::testing::TestWithParam<bool> {};

TEST_P(SnippetValidates, AsGlslEs300AndGlsl330Core) {
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
  const bool pack_mie = GetParam();
  Atmosphere earth = LoadAtmosphere("earth");
  glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, SmallSettings(pack_mie));
  std::string snippet = RuntimeSnippetSource(p, earth.wavelengths_nm, earth.name);
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
void ExpectGlMatchesTwin(GlContext* gl, const LutSet& luts, const std::string& source, const std::vector<Item>& items) {
  std::vector<testing::Vec4> inputs;
  for (const Item& item : items) {
    inputs.push_back({float(item.camera.x), float(item.camera.y), float(item.camera.z), float(item.what)});
    inputs.push_back({float(item.view.x), float(item.view.y), float(item.view.z), 0.0f});
    inputs.push_back({float(item.sun.x), float(item.sun.y), float(item.sun.z), item.shadow_length});
    inputs.push_back({float(item.extra.x), float(item.extra.y), float(item.extra.z), 0.0f});
  }
  std::vector<testing::Vec4> gpu = gl->RunFragmentPass(source, inputs, 4);
  ASSERT_EQ(gpu.size(), items.size());

  std::vector<vec3> twin;
  double max_value[kOutputCount] = {};
  for (const Item& item : items) {
    twin.push_back(EvaluateTwin(luts, item));
    for (int c = 0; c < 3; ++c) max_value[item.what] = std::max(max_value[item.what], twin.back()[c]);
  }
  // Relative difference where the value exceeds 1e-6 of its output's
  // maximum: 1e-3, the bound float32 evaluation should meet; llvmpipe stays
  // near 2e-5 for every output but aerial perspective. There the table
  // method subtracts two optical-depth lookups and computes
  // S(camera) - T S(point), both of which amplify the 0.5 m float rounding
  // of the point's radius near 6.4e6 m, most on short near-horizontal
  // segments. Segments under 10 km are therefore integrated along the
  // segment, with altitudes taken as the camera's plus the rise along the
  // ray; longer ones (long shadows' sunlit parts, grazing rays to the
  // ground) use the table method, whose transmittance differs by up to
  // about 2e-3, hence 3e-3 for it.
  // The radiance of short segments keeps one cancelling term: its multiple
  // scattering is the table method's S(x) - T S(p) over a 10 km stretch
  // minus that stretch's single scattering, a small difference in float of
  // table values interpolated by the driver. It ranges from about 2e-3 to
  // 1e-2 for the same snippet, depending only on how the driver compiles the
  // test's main() around it; hence 2e-2 for those radiances.
  auto tolerance = [](int what) {
    if (what == kAerialRadiance || what == kAerialRadianceInShadow) return 2e-2;
    return what == kAerialTransmittance ? 3e-3 : 1e-3;
  };
  double worst[kOutputCount] = {};
  std::map<std::string, double> worst_by_group;
  int compared = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    const Item& item = items[i];
    for (int c = 0; c < 3; ++c) {
      double expected = twin[i][c];
      ASSERT_TRUE(std::isfinite(gpu[i][c])) << kOutputNames[item.what];
      if (!(expected > 1e-6 * max_value[item.what])) continue;
      double relative = std::abs(gpu[i][c] / expected - 1.0);
      ++compared;
      worst[item.what] = std::max(worst[item.what], relative);
      worst_by_group[item.group] = std::max(worst_by_group[item.group], relative);
      EXPECT_LE(relative, tolerance(item.what)) << item.group << ", " << kOutputNames[item.what] << " channel " << c
                                      << ": GL " << gpu[i][c] << " twin " << expected << " camera z "
                                      << item.camera.z << " view " << item.view.x << "," << item.view.z
                                      << " sun " << item.sun.x << "," << item.sun.y << "," << item.sun.z
                                      << " extra " << item.extra.x << "," << item.extra.z;
    }
  }
  std::cout << gl->Description() << ": " << items.size() << " queries, " << compared
            << " values compared; max relative difference GL vs twin\n";
  for (int w = 0; w < kOutputCount; ++w) std::cout << "  " << kOutputNames[w] << ": " << worst[w] << "\n";
  for (const auto& [group, value] : worst_by_group) std::cout << "  group " << group << ": " << value << "\n";
}


TEST_P(SnippetOnMesa, MatchesTheCppTwin) {
  std::string why_not;
  std::unique_ptr<GlContext> gl = GlContext::Create(GetParam(), &why_not);
  if (!gl) GTEST_SKIP() << why_not;
  static const LutSet luts = Bake(LoadAtmosphere("earth"), SmallSettings(false));
  auto upload = [&](const char* sampler, const glsl::Texture& t) {
    gl->SetTexture(sampler, t.width, t.height, t.depth, t.texels);
  };
  upload("transmittance_texture", luts.transmittance);
  upload("scattering_texture", luts.scattering);
  upload("single_mie_scattering_texture", luts.single_mie_scattering);
  upload("irradiance_texture", luts.irradiance);

  std::vector<Item> items = MakeItems(luts.parameters.bottom_radius, luts.parameters.top_radius);
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
  BakeSettings settings = SmallSettings(false);
  ApplyScenePlan(plan, &planned, &settings);
  static const LutSet luts = Bake(planned, settings);
  gl->SetTexture("transmittance_texture", luts.transmittance.width, luts.transmittance.height, 1,
                 luts.transmittance.texels);
  for (const char* sampler : {"scattering_texture", "single_mie_scattering_texture"}) {
    gl->SetTexture(sampler, luts.scattering.width, luts.scattering.height, luts.scattering.depth,
                   luts.scattering.texels);
  }
  std::vector<Item> items;
  int aerial_items = 0;
  for (const Item& item : MakeItems(luts.parameters.bottom_radius, luts.parameters.top_radius)) {
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

INSTANTIATE_TEST_SUITE_P(Apis, SnippetOnMesa,
                         ::testing::Values(GlContext::Api::kGles30, GlContext::Api::kDesktop33Core),
                         [](const auto& info) { return info.param == GlContext::Api::kGles30 ? "Gles30" : "Desktop33Core"; });

}  // namespace
}  // namespace skybake
