// Scene files: strict parsing, what each effect keeps (tables, channels,
// shader functions), that the pruned GLSL still compiles, that a scene's
// set round-trips through its files, and that a scene bake reproduces the
// full bake inside the scene's ranges.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/scene.h"
#include "core/constants.h"
#include "core/errors.h"
#include "formats/lut_files.h"
#include "formats/lut_tables.h"
#include "formats/manifest.h"
#include "report/run_time_models.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/snippet.h"
#include "shaders_runtime/twin.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake {
namespace {


// A scene with the given [effects] lines, a ground camera, objects and all suns.
std::string SceneText(const std::string& effects, const std::string& extra = "") {
  const bool aerial = effects.find("aerial_perspective") != std::string::npos &&
                      effects.find("aerial_perspective = false") == std::string::npos;
  return "name = \"test\"\n[effects]\n" + effects + "\n[camera]\naltitude_km = [0, 2]\n" +
         (aerial ? "[objects]\naltitude_km = [0, 2]\n" : "") + "[sun]\nzenith_deg = [0, 90]\n" + extra;
}

std::string ParseError(const std::string& text) {
  try {
    ParseScene(text, "s.toml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<std::string> TableNames(const LutSet& luts) {
  std::vector<std::string> names;
  for (const TableDescription& t : DescribeTables(luts)) names.push_back(t.name);
  return names;
}

TEST(SceneFile, ExamplesParseAndFitEarth) {
  const Atmosphere earth = LoadAtmosphere("earth");
  int count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::filesystem::path(SKYBAKE_SOURCE_DIR) / "examples/scenes")) {
    if (entry.path().extension() != ".toml") continue;
    SCOPED_TRACE(entry.path().string());
    const Scene scene = LoadScene(entry.path().string());
    EXPECT_NO_THROW(ValidateSceneForAtmosphere(scene, earth, entry.path().filename().string()));
    ++count;
  }
  EXPECT_EQ(count, 4);
}

TEST(SceneFile, ReadsUnitsAndRanges) {
  const Scene s = ParseScene(SceneText("sky = true\naerial_perspective = { max_distance_km = 30 }",
                                       "[precision]\nscattering = \"half\"\n[output]\nformats = [\"ktx2\"]\n"),
                             "s.toml");
  EXPECT_TRUE(s.effects.sky);
  EXPECT_TRUE(s.effects.aerial_perspective);
  EXPECT_FALSE(s.effects.ground_irradiance);  // not named: not needed
  EXPECT_EQ(s.effects.aerial_perspective_max_distance_m, 30000.0);
  EXPECT_EQ(s.camera_altitude_max_m, 2000.0);
  EXPECT_EQ(s.sun_zenith_max_deg, 90.0);
  EXPECT_TRUE(s.precision.scattering_half);
  EXPECT_FALSE(s.precision.transmittance_half);
  EXPECT_EQ(s.formats, std::vector<std::string>{"ktx2"});
  // The manifest's JSON form reads back to the same scene.
  EXPECT_EQ(SceneToJson(SceneFromJson(SceneToJson(s))), SceneToJson(s));
  EXPECT_THROW(SceneFromJson("{\"name\": 1}"), InputError);
}

TEST(SceneFile, RejectsBadInputWithOneLineNamingTheKey) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {SceneText("sky = true\ncolour = true"), "s.toml: effects.colour: unknown key"},
      {SceneText("sky = 1"), "s.toml: effects.sky: expected true or false, got integer"},
      {SceneText("sky = true\naerial_perspective = true"), "effects.aerial_perspective: needs a maximum distance"},
      {SceneText("sky = true\naerial_perspective = { max_distance_km = -1 }"),
       "effects.aerial_perspective.max_distance_km = -1 must be > 0"},
      {SceneText("sky = false"), "s.toml: effects: names no effect"},
      {SceneText("sun_transmittance = true\nsharp_sun_halo = true"), "effects.sharp_sun_halo: needs sky"},
      {SceneText("sun_transmittance = true\nspace_views = true"), "effects.space_views: needs sky"},
      {SceneText("sky = true", "[precision]\nscattering = \"double\"\n"),
       "precision.scattering: unknown precision \"double\" (expected \"half\" or \"float\")"},
      {SceneText("sky = true", "[output]\nformats = [\"png\"]\n"),
       "output.formats[0]: unknown format \"png\" (expected \"exr\" or \"ktx2\")"},
      {"name = \"x\"\n[effects]\nsky = true\n[camera]\naltitude_km = [2, 1]\n[sun]\nzenith_deg = [0, 90]\n",
       "camera.altitude_km: minimum 2 exceeds maximum 1"},
      {"name = \"x\"\n[effects]\nsky = true\n[camera]\naltitude_km = [0, 1]\n[sun]\nzenith_deg = [0, 190]\n",
       "sun.zenith_deg[1] = 190 is outside [0, 180]"},
      {"name = \"x\"\n[effects]\nsky = true\n[camera]\naltitude_km = [0, 1]\n[objects]\naltitude_km = [0, 1]\n"
       "[sun]\nzenith_deg = [0, 90]\n",
       "objects: only meaningful with effects.aerial_perspective"},
      {"name = \"x\"\n[effects]\nsky = true\n[sun]\nzenith_deg = [0, 90]\n", "camera: missing required table"},
      {"name = \"x\"\n[effects\n", "s.toml:2:"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string error = ParseError(c.text);
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos);
  }
  // Altitudes are checked against the planet the scene is baked for.
  const Scene high = ParseScene("name = \"x\"\n[effects]\nsky = true\n[camera]\naltitude_km = [0, 100]\n"
                                "[sun]\nzenith_deg = [0, 90]\n",
                                "s.toml");
  try {
    ValidateSceneForAtmosphere(high, LoadAtmosphere("earth"), "s.toml");
    ADD_FAILURE() << "a camera above the atmosphere without space_views was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("enable effects.space_views"), std::string::npos) << e.what();
  }
}

// ---- what each effect keeps ----

TEST(ScenePlan, EachEffectKeepsExactlyItsTables) {
  const Atmosphere earth = LoadAtmosphere("earth");
  struct Case {
    std::string effects;
    std::vector<std::string> tables;  // as listed and written, in writing order
    bool packed;
    bool aerial_functions;
  };
  const std::vector<Case> cases = {
      {"sky = true", {"transmittance", "scattering"}, true, false},
      {"sky = true\nsharp_sun_halo = true", {"transmittance", "scattering", "single_mie_scattering"}, false, false},
      {"sky = true\nground_irradiance = true", {"transmittance", "irradiance", "scattering"}, true, false},
      {"aerial_perspective = { max_distance_km = 10 }", {"transmittance", "scattering"}, true, true},
      {"sun_transmittance = true", {"transmittance"}, false, false},
      {"ground_irradiance = true", {"transmittance", "irradiance"}, false, false},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.effects);
    const Scene scene = ParseScene(SceneText(c.effects), "s.toml");
    const ScenePlan plan = PlanScene(scene, earth);
    EXPECT_EQ(plan.pack_single_mie_in_alpha, c.packed);
    EXPECT_EQ(plan.aerial_perspective_functions, c.aerial_functions);
    // The tables a set of this scene lists (and so writes and loads).
    LutSet luts;
    luts.atmosphere = earth;
    BakeSettings settings = testing::SmallBakeSettings();
    Atmosphere planned = earth;
    ApplyScenePlan(plan, &planned, &settings);
    luts.parameters = MakeAtmosphereParameters(planned, settings);
    luts.scene = scene;
    EXPECT_EQ(TableNames(luts), c.tables);
    // Every table not kept is reported with its reason.
    for (const char* table : {"irradiance", "scattering", "single_mie_scattering"}) {
      const bool kept = std::find(c.tables.begin(), c.tables.end(), table) != c.tables.end();
      const bool reported = std::any_of(plan.omitted.begin(), plan.omitted.end(),
                                        [&](const OmittedTable& t) { return t.table == table && !t.reason.empty(); });
      EXPECT_NE(kept, reported) << table;
    }
    // Packed: the scattering table carries single Mie's red in alpha.
    for (const TableDescription& t : DescribeTables(luts)) {
      if (t.name == "scattering") {
        EXPECT_EQ(t.channels.size(), c.packed ? 4u : 3u);
      }
    }
  }
}

TEST(ScenePlan, SunRangeSetsTheLowestSunOfTheScatteringTable) {
  const Atmosphere earth = LoadAtmosphere("earth");
  const Scene scene = ParseScene(SceneText("sky = true"), "s.toml");
  // Independent geometry: from 2 km the horizon ray touches the ground at
  // acos(Rg / (Rg + 2 km)) from the camera and leaves the atmosphere at a
  // further acos(Rg / Rt); the sun there is that much lower than 90 degrees.
  const double rg = 6360e3, rt = 6420e3;
  const double expected = std::cos(kPi / 2 + std::acos(rg / (rg + 2e3)) + std::acos(rg / rt));
  EXPECT_NEAR(PlanScene(scene, earth).mu_s_min, expected, 1e-12);
  EXPECT_GT(PlanScene(scene, earth).mu_s_min, earth.mu_s_min);
  // Views from space keep the atmosphere's own range.
  const Scene space = ParseScene(SceneText("sky = true\nspace_views = true"), "s.toml");
  EXPECT_EQ(PlanScene(space, earth).mu_s_min, earth.mu_s_min);
}

TEST(ScenePlan, RestrictsTheScatteringTablesToWhatTheSceneShows) {
  const Atmosphere earth = LoadAtmosphere("earth");
  const double rg = 6360e3, rt = 6420e3;
  // Ground-level daytime, sky only: the cameras' altitudes and the suns
  // themselves, from the zenith to the horizon.
  ScenePlan sky = PlanScene(ParseScene(SceneText("sky = true"), "s.toml"), earth);
  ASSERT_TRUE(sky.restrict_scattering);
  EXPECT_EQ(sky.altitude_min_m, 0.0);
  EXPECT_EQ(sky.altitude_max_m, 2000.0);
  EXPECT_NEAR(sky.table_mu_s_min, 0.0, 1e-12);
  EXPECT_EQ(sky.table_mu_s_max, 1.0);
  // With aerial perspective to 30 km the sun is looked up at the objects,
  // up to the central angle of a 30 km chord away.
  ScenePlan aerial = PlanScene(ParseScene(SceneText("aerial_perspective = { max_distance_km = 30 }"), "s.toml"), earth);
  ASSERT_TRUE(aerial.restrict_scattering);
  EXPECT_NEAR(aerial.table_mu_s_min, std::cos(kPi / 2 + 2.0 * std::asin(15e3 / rg)), 1e-12);
  // Cameras and objects above the ground: a 150 km chord between two points
  // 1 km up dips to sqrt((rg + 1 km)^2 - (75 km)^2) - rg.
  const Scene high = ParseScene(
      "name = \"h\"\n[effects]\naerial_perspective = { max_distance_km = 150 }\n[camera]\naltitude_km = [1, 3]\n"
      "[objects]\naltitude_km = [1, 2]\n[sun]\nzenith_deg = [30, 60]\n",
      "h.toml");
  ScenePlan high_plan = PlanScene(high, earth);
  ASSERT_TRUE(high_plan.restrict_scattering);
  EXPECT_NEAR(high_plan.altitude_min_m, std::sqrt((rg + 1e3) * (rg + 1e3) - 75e3 * 75e3) - rg, 1e-6);
  EXPECT_EQ(high_plan.altitude_max_m, 3000.0);
  const double angle = 2.0 * std::asin(75e3 / rg);
  EXPECT_NEAR(high_plan.table_mu_s_min, std::cos(kPi / 3 + angle), 1e-12);
  EXPECT_NEAR(high_plan.table_mu_s_max, std::cos(kPi / 6 - angle), 1e-12);
  // From space every sun is seen; all altitudes: nothing to restrict.
  const Scene space = ParseScene(
      "name = \"s\"\n[effects]\nsky = true\nspace_views = true\n[camera]\naltitude_km = [0, 1000]\n"
      "[sun]\nzenith_deg = [0, 90]\n",
      "s.toml");
  EXPECT_FALSE(PlanScene(space, earth).restrict_scattering);
  // Cameras up to 20 km span 58% of the r axis's rho: not worth a second grid.
  std::string flight = SceneText("sky = true");
  flight.replace(flight.find("altitude_km = [0, 2]"), 20, "altitude_km = [0, 20]");
  EXPECT_FALSE(PlanScene(ParseScene(flight, "f.toml"), earth).restrict_scattering);

  // The table keeps 1.5 times the full table's r texel density over rho:
  // rho spans sqrt(2 km (2 rg + 2 km)) of sqrt(60 km (2 rg + 60 km)).
  Atmosphere planned = earth;
  BakeSettings settings;
  ApplyScenePlan(sky, &planned, &settings);
  const double span = std::sqrt(2e3 * (2.0 * rg + 2e3)) / std::sqrt((rt - rg) * (rt + rg));
  EXPECT_EQ(settings.scattering_r_size, static_cast<int>(std::ceil(1.5 * span * 31)) + 1);
  ASSERT_TRUE(settings.scattering_range.has_value());
  EXPECT_EQ(settings.scattering_range->atmosphere_r_size, 32);
  EXPECT_EQ(settings.higher_order_divisor, 2);  // earth is optically thin
  EXPECT_EQ(settings.scattering_range->atmosphere_mu_s_size, 16);  // the sun never sets
  // A sun that sets keeps every mu_s texel on the orders' grid.
  BakeSettings sunset_settings;
  Atmosphere sunset_planned = earth;
  ApplyScenePlan(PlanScene(ParseScene(SceneText("sky = true").replace(SceneText("sky = true").find("[0, 90]"), 7,
                                                                      "[80, 96]"),
                                      "s.toml"),
                           earth),
                 &sunset_planned, &sunset_settings);
  ASSERT_TRUE(sunset_settings.scattering_range.has_value());
  EXPECT_EQ(sunset_settings.scattering_range->atmosphere_mu_s_size, 32);
  // A thick atmosphere keeps each order's radiance on the full grid.
  Atmosphere fog = LoadAtmosphere("heavy-fog");
  BakeSettings fog_settings;
  ApplyScenePlan(PlanScene(ParseScene(SceneText("sky = true"), "s.toml"), fog), &fog, &fog_settings);
  EXPECT_EQ(fog_settings.higher_order_divisor, 1);
}

// ---- the pruned GLSL ----

std::string CallsFor(const SnippetParts& parts) {
  std::string body = "  vec3 t = GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, 6.4e6, 0.5);\n";
  if (parts.scattering) {
    body += "  vec3 tr;\n  t += GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, "
            "single_mie_scattering_texture, vec3(0.0, 0.0, 6.361e6), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), tr);\n";
  }
  if (parts.aerial_perspective) {
    body += "  vec3 ta;\n  t += GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture, "
            "single_mie_scattering_texture, vec3(0.0, 0.0, 6.361e6), vec3(1.0e3, 0.0, 6.361e6), "
            "vec3(0.0, 0.0, 1.0), ta);\n";
  }
  if (parts.irradiance) {
    body += "  vec3 sky;\n  t += GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, "
            "vec3(0.0, 0.0, 6.361e6), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), sky);\n";
  }
  return "uniform sampler2D transmittance_texture;\nuniform sampler3D scattering_texture;\n"
         "uniform sampler3D single_mie_scattering_texture;\nuniform sampler2D irradiance_texture;\n"
         "out vec4 skybake_output;\nvoid main() {\n" +
         body + "  skybake_output = vec4(t, 1.0);\n}\n";
}

int Validate(const testing::TempDir& dir, const std::string& source, std::string* out) {
  const std::filesystem::path file = dir.path() / "sky.frag";
  testing::WriteText(file, source);
  return testing::RunCommand(testing::ShellQuote(SKYBAKE_GLSLANG_VALIDATOR) + " " + testing::ShellQuote(file), dir,
                             out);
}

TEST(SceneSnippet, PrunedGlslCompilesAndLacksTheFunctionsLeftOut) {
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
  const Atmosphere earth = LoadAtmosphere("earth");
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, testing::SmallBakeSettings());
  testing::TempDir dir;
  for (const SnippetParts parts : {SnippetParts{true, true, true}, SnippetParts{true, false, false},
                                   SnippetParts{false, true, false}, SnippetParts{false, false, false},
                                   SnippetParts{true, false, true}}) {
    SCOPED_TRACE("scattering " + std::to_string(parts.scattering) + " irradiance " +
                 std::to_string(parts.irradiance) + " aerial " + std::to_string(parts.aerial_perspective));
    const std::string snippet = RuntimeSnippetSource(ShadingLanguage::kGlsl, p, earth.wavelengths_nm, earth.name, parts);
    for (const char* version : {"#version 300 es\n", "#version 330 core\n"}) {
      SCOPED_TRACE(version);
      std::string out;
      EXPECT_EQ(Validate(dir, version + snippet + CallsFor(parts), &out), 0) << out;
      // Each function left out is really gone: a shader calling it fails.
      for (int leave_out = 0; leave_out < 3; ++leave_out) {
        SnippetParts calls = parts;
        bool* call[] = {&calls.scattering, &calls.irradiance, &calls.aerial_perspective};
        if (*call[leave_out]) continue;
        *call[leave_out] = true;
        EXPECT_NE(Validate(dir, version + snippet + CallsFor(calls), &out), 0) << "function " << leave_out;
      }
    }
  }
}

// ---- the bake ----

// The twin's sky radiance (no distance) or aerial perspective for a query.
glsl::vec3 Radiance(const Twin& twin, const Query& q) {
  report::ReferenceCase c;
  c.query = q;
  return report::EvaluateTwin(twin, c).radiance;
}

TEST(SceneBake, AllEffectsFromSpaceBakeTheFullSet) {
  // A scene that needs everything changes nothing: same plan, same texels.
  const Atmosphere earth = LoadAtmosphere("earth");
  const Scene scene = ParseScene(
      "name = \"all\"\n[effects]\nsky = true\naerial_perspective = { max_distance_km = 100 }\n"
      "sun_transmittance = true\nground_irradiance = true\nsharp_sun_halo = true\nspace_views = true\n"
      "[camera]\naltitude_km = [0, 1000]\n[objects]\naltitude_km = [0, 60]\n[sun]\nzenith_deg = [0, 180]\n",
      "all.toml");
  Atmosphere planned = earth;
  BakeSettings settings = testing::SmallBakeSettings();
  ApplyScenePlan(PlanScene(scene, earth), &planned, &settings);
  const LutSet full = Bake(earth, testing::SmallBakeSettings());
  const LutSet pruned = Bake(planned, settings);
  EXPECT_EQ(pruned.transmittance.texels, full.transmittance.texels);
  EXPECT_EQ(pruned.scattering.texels, full.scattering.texels);
  EXPECT_EQ(pruned.single_mie_scattering.texels, full.single_mie_scattering.texels);
  EXPECT_EQ(pruned.irradiance.texels, full.irradiance.texels);
}

TEST(SceneBake, WritesAndLoadsOnlyTheKeptTables) {
  testing::TempDir dir;
  const std::filesystem::path scene_file = dir.path() / "ground.toml";
  testing::WriteText(scene_file, SceneText("sky = true\naerial_perspective = { max_distance_km = 30 }",
                                           "[precision]\nscattering = \"half\"\n[output]\nformats = [\"ktx2\"]\n"));
  const std::filesystem::path lut = dir.path() / "lut";
  std::string err;
  ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth -q -o " + testing::ShellQuote(lut) + " --scene " +
                                    testing::ShellQuote(scene_file) +
                                    " --orders 1 --transmittance-size 32 8 --irradiance-size 8 4"
                                    " --scattering-size 4 8 4 4 --ray-samples 8 --sphere-samples 4",
                                dir, nullptr, &err),
            0)
      << err;
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(lut)) files.push_back(entry.path().filename());
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"atmosphere_constants.glsl", "atmosphere_constants.hlsl",
                                             "atmosphere_constants.metal", "atmosphere_constants.wgsl",
                                             "definitions.glsl", "definitions.hlsl", "definitions.metal",
                                             "functions.glsl", "functions.hlsl", "functions.metal", "functions.wgsl",
                                             "scattering.ktx2", "skybake.json", "transmittance.ktx2"}));
  const Manifest manifest = ReadManifest(lut);
  ASSERT_TRUE(manifest.luts.scene.has_value());
  EXPECT_EQ(manifest.luts.scene->name, "test");
  for (const ManifestFile& f : manifest.table_files) {
    EXPECT_EQ(f.pixel_type, f.table == "scattering" ? PixelType::kHalf : PixelType::kFloat) << f.table;
  }
  const std::string constants = testing::ReadText(lut / "atmosphere_constants.glsl");
  EXPECT_NE(constants.find("#define SKYBAKE_HAS_IRRADIANCE_TEXTURE 0"), std::string::npos);
  EXPECT_NE(constants.find("#define SKYBAKE_HAS_AERIAL_PERSPECTIVE 1"), std::string::npos);
  const LutSet loaded = LoadLutSet(lut);
  EXPECT_TRUE(loaded.irradiance.texels.empty());
  EXPECT_TRUE(loaded.single_mie_scattering.texels.empty());
  EXPECT_FALSE(loaded.scattering.texels.empty());

  // eval: a query inside the scene is answered, one outside is refused with
  // exit 2 and one line, or clamped with a warning under --clamp.
  const std::filesystem::path inside = dir.path() / "inside.csv", outside = dir.path() / "outside.csv";
  testing::WriteText(inside, "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n100,60,30,0\n");
  testing::WriteText(outside, "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n100,60,95,0\n");
  const std::string eval = testing::Skybake() + " eval " + testing::ShellQuote(lut) + " --in ";
  EXPECT_EQ(testing::RunCommand(eval + testing::ShellQuote(inside), dir, nullptr, &err), 0) << err;
  EXPECT_EQ(testing::RunCommand(eval + testing::ShellQuote(outside), dir, nullptr, &err), 2);
  EXPECT_NE(err.find("sun_zenith_deg = 95 is outside the scene's [0, 90]"), std::string::npos) << err;
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_EQ(testing::RunCommand(eval + testing::ShellQuote(outside) + " --clamp", dir, nullptr, &err), 0) << err;
  EXPECT_NE(err.find("warning:"), std::string::npos) << err;
  const std::filesystem::path normal = dir.path() / "normal.csv";
  testing::WriteText(normal,
                     "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,normal_zenith_deg\n0,60,30,0,0\n");
  EXPECT_EQ(testing::RunCommand(eval + testing::ShellQuote(normal) + " --clamp", dir, nullptr, &err), 2);
  EXPECT_NE(err.find("irradiance (normal_zenith_deg) is not in the scene"), std::string::npos) << err;

  // render: the panorama shows the ground, which this scene does not light.
  const std::string render = testing::Skybake() + " render " + testing::ShellQuote(lut) + " -q -o " +
                             testing::ShellQuote(dir.path() / "render") + " --size 8 --sun-zenith 30";
  EXPECT_EQ(testing::RunCommand(render + " --views panorama", dir, nullptr, &err), 2);
  EXPECT_NE(err.find("view 'panorama' (the ground"), std::string::npos) << err;
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "render"));
  EXPECT_EQ(testing::RunCommand(render + " --views fisheye", dir, nullptr, &err), 0) << err;
}

TEST(SceneBake, CompareFullReportsBytesTimeAndAccuracyInsideTheScene) {
  testing::TempDir dir;
  const std::filesystem::path scene_file = dir.path() / "ground.toml";
  testing::WriteText(scene_file, SceneText("sky = true\nground_irradiance = true"));
  const std::string small =
      " --orders 2 --transmittance-size 32 8 --irradiance-size 8 4 --scattering-size 8 16 8 4 --ray-samples 16"
      " --sphere-samples 4";
  auto bake = [&](const std::string& atmosphere, const std::string& extra, std::string* out, std::string* err) {
    return testing::RunCommand(testing::Skybake() + " bake " + atmosphere + " -q --json -o " +
                                   testing::ShellQuote(dir.path() / atmosphere) + " --scene " +
                                   testing::ShellQuote(scene_file) + small + extra,
                               dir, out, err);
  };
  std::string out, err;
  ASSERT_EQ(bake("earth", " --compare-full", &out, &err), 0) << err;
  const nlohmann::json comparison = nlohmann::json::parse(out)["scene"]["comparison"];
  EXPECT_LT(comparison["scene_table_bytes"].get<double>(), comparison["full_table_bytes"].get<double>());
  // Earth's committed reference: the sky and irradiance cases with cameras
  // below 2 km and the sun above the horizon.
  const nlohmann::json& accuracy = comparison["accuracy"];
  EXPECT_EQ(accuracy["reference"], "earth_reference.csv, earth_twilight_reference.csv, "
                                   "earth_twilight_between_reference.csv, earth_aerial_horizon_reference.csv");
  EXPECT_GT(accuracy["cases"].get<int>(), 50);
  for (const char* quantity : {"radiance", "sun_irradiance", "sky_irradiance"}) {
    for (const char* bake_name : {"scene", "full"}) {
      const nlohmann::json& e = accuracy["errors"][quantity][bake_name];
      EXPECT_GT(e["values"].get<int>(), 0) << quantity;
      EXPECT_GE(e["max_relative"].get<double>(), e["rms_relative"].get<double>()) << quantity;
      EXPECT_GE(e["rms_relative"].get<double>(), e["mean_relative"].get<double>()) << quantity;
    }
  }
  // No reference for mars: said so, no accuracy.
  ASSERT_EQ(bake("mars", " --compare-full", &out, &err), 0) << err;
  EXPECT_FALSE(nlohmann::json::parse(out)["scene"]["comparison"].contains("accuracy"));
  // --reference needs --compare-full.
  EXPECT_EQ(bake("earth", " --reference x.csv", &out, &err), 1);
  EXPECT_NE(err.find("--reference: needs --compare-full"), std::string::npos) << err;
}

TEST(SceneBake, ReproducesTheFullBakeInsideTheScenesRanges) {
  // Ground-level daytime scene with a separate single Mie table: its tables
  // cover the scene's altitudes and suns, their higher orders gathered from
  // a grid over the whole atmosphere. Both it and the full bake at the same
  // sizes are compared with a finer full bake (twice the mu_s and r
  // texels) at sky and aerial-perspective queries inside the scene.
  const Atmosphere earth = LoadAtmosphere("earth");
  const Scene scene =
      ParseScene(SceneText("sky = true\nsharp_sun_halo = true\naerial_perspective = { max_distance_km = 30 }"),
                 "s.toml");
  BakeSettings settings = testing::SmallBakeSettings();
  settings.scattering_mu_s_size = 16;
  Atmosphere planned = earth;
  BakeSettings scene_settings = settings;
  ApplyScenePlan(PlanScene(scene, earth), &planned, &scene_settings);
  BakeSettings fine = settings;
  fine.scattering_mu_s_size = 64;
  fine.scattering_r_size = 16;
  const LutSet full_luts = Bake(earth, settings), scene_luts = Bake(planned, scene_settings),
               fine_luts = Bake(earth, fine);
  const Twin full(MakeTwinTables(full_luts)), pruned(MakeTwinTables(scene_luts)), reference(MakeTwinTables(fine_luts));
  double full_error = 0.0, scene_error = 0.0, full_largest = 0.0, scene_largest = 0.0;
  int n = 0;
  for (double altitude : {0.0, 1000.0, 2000.0}) {
    for (double vz : {0.0, 45.0, 80.0, 89.0, 95.0}) {
      for (double sz = 0.0; sz <= 90.0; sz += 7.5) {
        for (double distance : {0.0, 1000.0, 10000.0, 25000.0}) {
          Query q;
          q.altitude_m = altitude, q.view_zenith_deg = vz, q.sun_zenith_deg = sz, q.view_sun_azimuth_deg = 60.0;
          q.distance_m = distance;
          std::vector<std::string> unused;
          if (!SceneQueryProblem(scene, earth.bottom_radius_m, false, &q, &unused).empty()) continue;
          const glsl::vec3 ref = Radiance(reference, q);
          const glsl::vec3 a = Radiance(full, q), b = Radiance(pruned, q);
          for (int c = 0; c < 3; ++c) {
            ASSERT_TRUE(std::isfinite(b[c]));
            if (ref[c] <= 0.0) continue;  // looking down from the ground: no air to scatter
            const double full_relative = std::abs(a[c] - ref[c]) / ref[c];
            const double scene_relative = std::abs(b[c] - ref[c]) / ref[c];
            full_error += full_relative, scene_error += scene_relative;
            full_largest = std::max(full_largest, full_relative);
            scene_largest = std::max(scene_largest, scene_relative);
            ++n;
          }
        }
      }
    }
  }
  ASSERT_GT(n, 700);
  full_error /= n, scene_error /= n;
  std::cout << "relative difference to the finer bake, mean / largest: full " << full_error << " / " << full_largest
            << ", scene " << scene_error << " / " << scene_largest << "\n";
  // The scene spends the r and mu_s texels on its altitudes and suns: no
  // worse than the full bake at equal sizes, on average (5% slack: the two
  // grids favour different queries) and at the worst query (25% slack: one
  // query).
  EXPECT_LE(scene_error, full_error * 1.05);
  EXPECT_LE(scene_largest, full_largest * 1.25);
}

// Every example scene's bake at the default sizes against the full bake, on
// the committed Earth cases inside the scene (`skybake bake --scene
// --compare-full`, the figures of examples/scenes/README.md): no worse in
// RMS nor at the worst case, for each quantity with cases. Scenes whose
// tables are not restricted bake the full tables, so theirs are equal (the
// slack is rounding).
TEST(ExampleScenes, BakeIsNoWorseThanTheFullBakeOnItsCases) {
  testing::TempDir dir;
  const std::filesystem::path scenes = std::filesystem::path(SKYBAKE_SOURCE_DIR) / "examples" / "scenes";
  int compared = 0;
  for (const auto& entry : std::filesystem::directory_iterator(scenes)) {
    if (entry.path().extension() != ".toml") continue;
    const std::string name = entry.path().stem().string();
    std::string out, err;
    ASSERT_EQ(testing::RunCommand(testing::Skybake() + " bake earth -q --json --compare-full -o " +
                                      testing::ShellQuote(dir.path() / name) + " --scene " +
                                      testing::ShellQuote(entry.path()),
                                  dir, &out, &err),
              0)
        << name << ": " << err;
    const nlohmann::json accuracy = nlohmann::json::parse(out)["scene"]["comparison"]["accuracy"];
    ASSERT_GT(accuracy["cases"].get<int>(), 40) << name;
    for (const auto& [quantity, errors] : accuracy["errors"].items()) {
      const nlohmann::json &scene = errors["scene"], &full = errors["full"];
      std::cout << name << " " << quantity << ": scene RMS " << scene["rms_relative"] << " max "
                << scene["max_relative"] << ", full RMS " << full["rms_relative"] << " max " << full["max_relative"]
                << "\n";
      constexpr double kRounding = 1e-6;
      EXPECT_LE(scene["rms_relative"].get<double>(), full["rms_relative"].get<double>() * (1.0 + kRounding))
          << name << " " << quantity;
      EXPECT_LE(scene["max_relative"].get<double>(), full["max_relative"].get<double>() * (1.0 + kRounding))
          << name << " " << quantity;
    }
    ++compared;
  }
  EXPECT_EQ(compared, 4);
}

}  // namespace
}  // namespace skybake
