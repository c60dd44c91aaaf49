// Bakes in a pipeline, through the skybake executable: output folders an
// engine project can live in (PipelineDefects.D06_*: files skybake did not
// write never block a bake, and what does block one is refused before the
// bake), and incremental bakes (IncrementalBake.*): a set whose manifest
// records the same inputs is left as it is, any changed input bakes again,
// and the depfile tells a build system what a bake read.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;
using testing::WriteText;

const std::string& kSmall = testing::kSmallBakeOptions;

// `text` with `from` replaced by `to`.
std::string Replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

fs::path Source(const std::string& relative) { return fs::path(SKYBAKE_SOURCE_DIR) / relative; }

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct BakeRun {
  int exit_code = -1;
  json report;  // stdout's --json report; null unless it parses
  std::string err;
  bool Skipped() const { return report.is_object() && report.value("skipped", false); }
};

// `skybake bake ARGS --json`.
BakeRun Bake(const TempDir& dir, const std::string& args) {
  BakeRun run;
  std::string out;
  run.exit_code = RunCommand(Skybake() + " bake " + args + " --json", dir, &out, &run.err);
  run.report = json::parse(out, nullptr, /*allow_exceptions=*/false);
  return run;
}

// Writes the earth preset's file as `file` in `dir`, with `from` replaced by `to`.
fs::path WriteEarth(const TempDir& dir, const std::string& file, const std::string& from = {},
                    const std::string& to = {}) {
  const std::string text = ReadText(Source("examples/atmospheres/earth.toml"));
  WriteText(dir.path() / file, from.empty() ? text : Replaced(text, from, to));
  return dir.path() / file;
}

// ---- issue 50, defect 6: output folders an engine project can live in ----

TEST(PipelineDefects, D06_FilesSkybakeDidNotWriteNeverBlockABake) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  fs::create_directories(out / "Editor");
  WriteText(out / "README.txt", "the sky tables of level 3");
  WriteText(out / "transmittance.ktx2.meta", "guid: 1234");
  // A folder holding only foreign files bakes (it used to bake, then exit 3).
  BakeRun first = Bake(dir, "earth -o " + ShellQuote(out) + kSmall);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // Re-bakes of other settings, with and without --clean, leave them too.
  BakeRun second = Bake(dir, "earth --transmittance-samples 32 -o " + ShellQuote(out) + kSmall);
  ASSERT_EQ(second.exit_code, 0) << second.err;
  BakeRun cleaned = Bake(dir, "earth --clean --format ktx2 -o " + ShellQuote(out) + kSmall);
  ASSERT_EQ(cleaned.exit_code, 0) << cleaned.err;
  EXPECT_FALSE(fs::exists(out / "transmittance.exr"));  // the earlier set's, removed by --clean
  EXPECT_EQ(ReadText(out / "README.txt"), "the sky tables of level 3");
  EXPECT_EQ(ReadText(out / "transmittance.ktx2.meta"), "guid: 1234");
  EXPECT_TRUE(fs::is_directory(out / "Editor"));
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir, nullptr, &err), 0) << err;
}

TEST(PipelineDefects, D06_AnEarlierSetsTablesAreRefusedBeforeTheBake) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  ASSERT_EQ(Bake(dir, "earth -q -o " + ShellQuote(out) + kSmall).exit_code, 0);
  const std::string manifest = ReadText(out / "skybake.json");
  // EXR only would leave the earlier set's KTX2 tables beside the new
  // manifest: refused with one line, and before anything is baked.
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bake earth --format exr -o " + ShellQuote(out) + kSmall, dir, nullptr, &err), 3);
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_TRUE(Contains(err, "scattering.ktx2") && Contains(err, "--clean")) << err;
  EXPECT_FALSE(Contains(err, "baking")) << err;
  EXPECT_EQ(ReadText(out / "skybake.json"), manifest);
}

TEST(PipelineDefects, D06_AnEmptyOutputIsAUsageErrorAtOnce) {
  TempDir dir;
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o ''" + kSmall, dir, nullptr, &err), 1);
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_TRUE(Contains(err, "-o")) << err;
  EXPECT_FALSE(Contains(err, "baking")) << err;
}

// The same for every option that names an output: one line, exit 1, before any work.
TEST(PipelineDefects, D06_EveryOutputOptionRefusesAnEmptyPathAtOnce) {
  TempDir dir;
  for (const std::string& command :
       {std::string("render earth -o ''"), std::string("report earth -o ''"), std::string("fit earth -o ''"),
        std::string("bench earth -o ''"), std::string("info earth --plot ''"),
        std::string("eval earth --in x.csv --out ''"), std::string("reference earth --in x.csv --out ''"),
        std::string("bake earth -o out --depfile ''")}) {
    std::string err;
    EXPECT_EQ(RunCommand(Skybake() + " " + command, dir, nullptr, &err), 1) << command << ": " << err;
    EXPECT_EQ(testing::Lines(err).size(), 1u) << command << ": " << err;
    EXPECT_TRUE(Contains(err, "an empty path")) << command << ": " << err;
  }
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

// ---- incremental bakes ----

TEST(IncrementalBake, ASecondBakeOfUnchangedInputsIsSkipped) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string args = "earth -o " + ShellQuote(out) + kSmall;
  BakeRun first = Bake(dir, args);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_FALSE(first.Skipped());
  const std::string manifest = ReadText(out / "skybake.json");
  const fs::file_time_type manifest_time = fs::last_write_time(out / "skybake.json");
  const fs::file_time_type table_time = fs::last_write_time(out / "scattering.ktx2");
  EXPECT_EQ(json::parse(manifest)["inputs_sha256"], first.report["inputs_sha256"]);

  BakeRun second = Bake(dir, args);
  ASSERT_EQ(second.exit_code, 0) << second.err;
  EXPECT_TRUE(second.Skipped()) << second.report.dump(2);
  EXPECT_TRUE(Contains(second.err, "up to date")) << second.err;
  EXPECT_FALSE(Contains(second.err, "baking")) << second.err;
  // The manifest's figures, and nothing written.
  EXPECT_EQ(second.report["inputs_sha256"], first.report["inputs_sha256"]);
  EXPECT_EQ(second.report["orders_used"], first.report["orders_used"]);
  EXPECT_EQ(second.report["files"], first.report["files"]);
  EXPECT_EQ(second.report["tables"], first.report["tables"]);
  // Loosely: the target (< 50 ms) is measured, not asserted here.
  EXPECT_LT(second.report["total_seconds"].get<double>(), 1.0);
  EXPECT_EQ(ReadText(out / "skybake.json"), manifest);
  EXPECT_EQ(fs::last_write_time(out / "skybake.json"), manifest_time);
  EXPECT_EQ(fs::last_write_time(out / "scattering.ktx2"), table_time);

  // The threads, -q, --clean and the way the atmosphere is named change no file.
  BakeRun third = Bake(dir, "preset:earth --threads 1 -q --clean -o " + ShellQuote(out) + kSmall);
  ASSERT_EQ(third.exit_code, 0) << third.err;
  EXPECT_TRUE(third.Skipped());
}

TEST(IncrementalBake, TheResolvedAtmosphereCountsNotItsText) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const fs::path earth = WriteEarth(dir, "earth.toml");
  ASSERT_EQ(Bake(dir, ShellQuote(earth) + " -q -o " + ShellQuote(out) + kSmall).exit_code, 0);
  // A comment, and the same radius in metres instead of kilometres: the same atmosphere.
  WriteEarth(dir, "earth.toml", "# Earth's clear sky", "# Earth's clear sky, as the level uses it");
  EXPECT_TRUE(Bake(dir, ShellQuote(earth) + " -q -o " + ShellQuote(out) + kSmall).Skipped());
  WriteEarth(dir, "earth.toml", "ground_radius_km = 6360.0", "ground_radius_m = 6360000.0");
  EXPECT_TRUE(Bake(dir, ShellQuote(earth) + " -q -o " + ShellQuote(out) + kSmall).Skipped());
  // A value the atmosphere resolves to differently bakes again.
  WriteEarth(dir, "earth.toml", "ground_albedo = 0.1", "ground_albedo = 0.3");
  BakeRun changed = Bake(dir, ShellQuote(earth) + " -q -o " + ShellQuote(out) + kSmall);
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_FALSE(changed.Skipped());
  EXPECT_EQ(json::parse(ReadText(out / "skybake.json"))["atmosphere"]["planet"]["ground_albedo"][0], 0.3);
}

TEST(IncrementalBake, EachChangedInputBakesAgain) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string base = "earth -q --clean -o " + ShellQuote(out) + kSmall;
  ASSERT_EQ(Bake(dir, base).exit_code, 0);
  ASSERT_TRUE(Bake(dir, base).Skipped());
  // Each changes the files; each is baked once, then found up to date, and
  // the base bakes again after it.
  const std::vector<std::string> changed_bakes = {
      Replaced(base, "--transmittance-size 64 16", "--transmittance-size 32 16"),
      Replaced(base, "--scattering-size 8 32 8 4", "--scattering-size 8 32 8 6"),
      Replaced(base, "--orders 2", "--orders 3"),
      Replaced(base, "--ray-samples 32", "--ray-samples 16"),
      base + " --transmittance-samples 32",
      base + " --higher-order-divisor 2",
      base + " --pack-mie",
      base + " --format ktx2",
      base + " --half",
      base + " --ktx2-supercompression zstd",
      base + " --runtime glsl",
  };
  for (const std::string& args : changed_bakes) {
    SCOPED_TRACE(args);
    BakeRun changed = Bake(dir, args);
    ASSERT_EQ(changed.exit_code, 0) << changed.err;
    EXPECT_FALSE(changed.Skipped());
    EXPECT_TRUE(Bake(dir, args).Skipped());
    BakeRun back = Bake(dir, base);
    ASSERT_EQ(back.exit_code, 0) << back.err;
    EXPECT_FALSE(back.Skipped());
  }
}

TEST(IncrementalBake, AChangedSceneOrWavelengthCountBakesAgain) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string scene = ReadText(Source("examples/scenes/ground-daytime-game.toml"));
  const fs::path scene_file = dir.path() / "game.toml";
  WriteText(scene_file, scene);
  const std::string with_scene = "earth -q --clean --scene " + ShellQuote(scene_file) + " -o " + ShellQuote(out) + kSmall;
  ASSERT_EQ(Bake(dir, with_scene).exit_code, 0);
  EXPECT_TRUE(Bake(dir, with_scene).Skipped());
  WriteText(scene_file, Replaced(scene, "zenith_deg = [0.0, 90.0]", "zenith_deg = [0.0, 80.0]"));
  BakeRun changed = Bake(dir, with_scene);
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_FALSE(changed.Skipped());
  EXPECT_TRUE(Bake(dir, with_scene).Skipped());

  const std::string spectral = "earth -q --clean --wavelengths 6 -o " + ShellQuote(out) + kSmall;
  BakeRun colour = Bake(dir, spectral);
  ASSERT_EQ(colour.exit_code, 0) << colour.err;
  EXPECT_FALSE(colour.Skipped());
  EXPECT_TRUE(Bake(dir, spectral).Skipped());
  EXPECT_FALSE(Bake(dir, spectral + " --spectral-higher-orders exact").Skipped());
  EXPECT_FALSE(Bake(dir, "earth -q --clean --wavelengths 9 -o " + ShellQuote(out) + kSmall).Skipped());
}

TEST(IncrementalBake, AMissingOrTruncatedFileBakesAgain) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string args = "earth -q -o " + ShellQuote(out) + kSmall;
  ASSERT_EQ(Bake(dir, args).exit_code, 0);
  const std::string table = ReadText(out / "scattering.ktx2");

  fs::remove(out / "irradiance.exr");
  BakeRun deleted = Bake(dir, args);
  ASSERT_EQ(deleted.exit_code, 0) << deleted.err;
  EXPECT_FALSE(deleted.Skipped());
  EXPECT_TRUE(fs::exists(out / "irradiance.exr"));

  fs::resize_file(out / "scattering.ktx2", table.size() / 2);
  BakeRun truncated = Bake(dir, args);
  ASSERT_EQ(truncated.exit_code, 0) << truncated.err;
  EXPECT_FALSE(truncated.Skipped());
  EXPECT_EQ(ReadText(out / "scattering.ktx2"), table);

  fs::remove(out / "functions.glsl");
  EXPECT_FALSE(Bake(dir, args).Skipped());
  EXPECT_TRUE(Bake(dir, args).Skipped());
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir, nullptr, &err), 0) << err;
}

TEST(IncrementalBake, ForceBakesAnUpToDateSet) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string args = "earth -q -o " + ShellQuote(out) + kSmall;
  ASSERT_EQ(Bake(dir, args).exit_code, 0);
  ASSERT_TRUE(Bake(dir, args).Skipped());
  BakeRun forced = Bake(dir, args + " --force");
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_FALSE(forced.Skipped());
  EXPECT_GT(forced.report["timings"].size(), 1u);
}

TEST(IncrementalBake, AManifestWithoutTheInputsHashBakesAgain) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  const std::string args = "earth -q -o " + ShellQuote(out) + kSmall;
  ASSERT_EQ(Bake(dir, args).exit_code, 0);
  // As written before the hash was recorded: still a valid set, baked again.
  json manifest = json::parse(ReadText(out / "skybake.json"));
  manifest.erase("inputs_sha256");
  WriteText(out / "skybake.json", manifest.dump(2) + "\n");
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir, nullptr, &err), 0) << err;
  EXPECT_FALSE(Bake(dir, args).Skipped());
  EXPECT_TRUE(Bake(dir, args).Skipped());
}

TEST(IncrementalBake, ABatchSkipsEachUpToDateAtmosphere) {
  TempDir dir;
  const fs::path earth = WriteEarth(dir, "earth.toml");
  const std::string args = ShellQuote(earth) + " mars -q -o " + ShellQuote(dir.path() / "{name}") + kSmall;
  ASSERT_EQ(Bake(dir, args).exit_code, 0);
  BakeRun again = Bake(dir, args);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  ASSERT_EQ(again.report["bakes"].size(), 2u) << again.report.dump(2);
  EXPECT_TRUE(again.report["bakes"][0].value("skipped", false));
  EXPECT_TRUE(again.report["bakes"][1].value("skipped", false));
  WriteEarth(dir, "earth.toml", "ground_albedo = 0.1", "ground_albedo = 0.2");
  BakeRun one_changed = Bake(dir, args);
  ASSERT_EQ(one_changed.exit_code, 0) << one_changed.err;
  EXPECT_FALSE(one_changed.report["bakes"][0].value("skipped", true));
  EXPECT_TRUE(one_changed.report["bakes"][1].value("skipped", false));
}

TEST(IncrementalBake, TheDepfileNamesTheManifestAndTheFilesRead) {
  TempDir dir;
  const fs::path folder = dir.path() / "a folder";
  fs::create_directories(folder);
  const fs::path earth = WriteEarth(dir, "a folder/earth.toml");
  const fs::path scene = folder / "game.toml";
  WriteText(scene, ReadText(Source("examples/scenes/ground-daytime-game.toml")));
  const fs::path out = dir.path() / "sky";
  const fs::path depfile = dir.path() / "sky.d";
  auto escaped = [](const fs::path& p) {
    std::string text;
    for (char c : p.string()) text += c == ' ' ? std::string("\\ ") : std::string(1, c);
    return text;
  };
  const std::string rule =
      escaped(out / "skybake.json") + ": " + escaped(earth) + " " + escaped(scene) + "\n";
  const std::string args = ShellQuote(earth) + " -q --scene " + ShellQuote(scene) + " --depfile " + ShellQuote(depfile) + " -o " +
                           ShellQuote(out) + kSmall;
  BakeRun baked = Bake(dir, args);
  ASSERT_EQ(baked.exit_code, 0) << baked.err;
  EXPECT_EQ(ReadText(depfile), rule);
  fs::remove(depfile);
  ASSERT_TRUE(Bake(dir, args).Skipped());
  EXPECT_EQ(ReadText(depfile), rule);  // a skipped bake writes it too

  // A preset is inside the program: the manifest depends on no file.
  ASSERT_EQ(Bake(dir, "earth -q --clean --depfile " + ShellQuote(depfile) + " -o " + ShellQuote(out) + kSmall).exit_code, 0);
  EXPECT_EQ(ReadText(depfile), escaped(out / "skybake.json") + ":\n");
  // One set per depfile.
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bake earth mars --depfile " + ShellQuote(depfile) + " -o " +
                           ShellQuote(dir.path() / "{name}") + kSmall,
                       dir, nullptr, &err),
            1);
  EXPECT_TRUE(Contains(err, "--depfile")) << err;
}

}  // namespace
}  // namespace skybake
