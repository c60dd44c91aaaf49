// The command line as a newcomer and a build script use it: the defects
// NewcomerDefects.D<N>_* each reproduce (numbered as in docs/cli.md's list of
// fixed defects), and the pipeline features around them: output folders a
// pipeline can trust, presets that cannot be shadowed, batch bakes, stress on
// a user's file, machine-readable errors and interrupts.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "formats/lut_files.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;
using testing::WriteText;

const std::string kSmall = " -q" + testing::kSmallBakeOptions;

std::string Examples(const std::string& relative) {
  return ShellQuote((fs::path(SKYBAKE_SOURCE_DIR) / "examples" / relative).string());
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// ---- the numbered defects ----

TEST(NewcomerDefects, D02_QuickReportRunsWithItsDefaultOrders) {
  TempDir dir;
  std::string err;
  // No --orders: the base bake keeps the default 4 while the quick ladder bakes orders 1-3.
  EXPECT_EQ(RunCommand(Skybake() + " report earth -o " + ShellQuote(dir.path() / "report") +
                           " --quick -q --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4"
                           " --ray-samples 32 --sphere-samples 8 --march-steps 4 --passes 1",
                       dir, nullptr, &err),
            0)
      << err;
  EXPECT_TRUE(fs::exists(dir.path() / "report" / "report.json"));
  // auto is still refused, as a usage error.
  EXPECT_EQ(RunCommand(Skybake() + " report earth -o " + ShellQuote(dir.path() / "r2") + " --quick --orders auto", dir,
                       nullptr, &err),
            1)
      << err;
}

TEST(NewcomerDefects, D04_BakeRefusesAFolderHoldingAnotherSetsFiles) {
  TempDir dir;
  const fs::path out = dir.path() / "set";
  std::string out_text, err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(out) + kSmall, dir, nullptr, &err), 0) << err;
  const std::string earth_manifest = ReadText(out / "skybake.json");

  // mars in EXR only would leave earth's .ktx2 files beside mars's manifest.
  EXPECT_EQ(RunCommand(Skybake() + " bake mars --format exr -o " + ShellQuote(out) + kSmall, dir, nullptr, &err), 3);
  EXPECT_TRUE(Contains(err, "scattering.ktx2")) << err;
  EXPECT_EQ(testing::Lines(err).size(), 1u) << err;
  EXPECT_EQ(ReadText(out / "skybake.json"), earth_manifest);  // nothing was written

  // --clean removes exactly the earlier set's files the new set does not
  // list; a file no skybake set listed is left alone.
  WriteText(out / "notes.txt", "mine");
  ASSERT_EQ(RunCommand(Skybake() + " bake mars --format exr --clean -o " + ShellQuote(out) + kSmall, dir, nullptr, &err),
            0)
      << err;
  for (const char* gone : {"transmittance.ktx2", "irradiance.ktx2", "scattering.ktx2", "single_mie_scattering.ktx2"}) {
    EXPECT_FALSE(fs::exists(out / gone)) << gone;
  }
  EXPECT_TRUE(fs::exists(out / "scattering.exr"));
  EXPECT_EQ(ReadText(out / "notes.txt"), "mine");
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(out), dir, nullptr, &err), 0) << err;
}

TEST(NewcomerDefects, D05_AFolderNamedLikeAPresetDoesNotHideIt) {
  TempDir dir;
  std::string err;
  // The second bake into ./earth used to read the folder as the atmosphere.
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " bake earth -o earth" + kSmall, dir,
                         nullptr, &err),
              0)
        << "bake " << i << ": " << err;
  }
  EXPECT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate preset:earth", dir), 0);
  // A path is always a path: ./earth is the folder.
  EXPECT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate ./earth", dir, nullptr, &err), 3);
  EXPECT_TRUE(Contains(err, "is a directory")) << err;
  // A file spelled like a preset is reached as ./NAME; the bare word stays the preset.
  WriteText(dir.path() / "mars", ReadText(fs::path(SKYBAKE_SOURCE_DIR) / "examples/atmospheres/light-fog.toml"));
  std::string out;
  ASSERT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate mars --json", dir, &out), 0);
  EXPECT_EQ(nlohmann::json::parse(out)["name"], "mars");
  ASSERT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate ./mars --json", dir, &out), 0);
  EXPECT_EQ(nlohmann::json::parse(out)["name"], "light-fog");
  EXPECT_EQ(RunCommand(Skybake() + " validate preset:nonesuch", dir, nullptr, &err), 2);
}

TEST(NewcomerDefects, D06_EvalClampMovesObjectsIntoTheScenesAltitudes) {
  TempDir dir;
  const fs::path set = dir.path() / "scene";
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth --scene " + Examples("scenes/ground-daytime-game.toml") + " -o " +
                           ShellQuote(set) + kSmall,
                       dir, nullptr, &err),
            0)
      << err;
  // Objects live at 0-2 km: 20 km at 60 degrees from the zenith ends 10 km up.
  WriteText(dir.path() / "q.csv",
            "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,distance_m\n"
            "100,80,30,0,1000\n"
            "\n"
            "100,60,30,0,20000\n");
  EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(set) + " --in " + ShellQuote(dir.path() / "q.csv"), dir, &out, &err),
            2);
  // Located as every other file error, by line (the third row of text is line 4).
  EXPECT_EQ(err.rfind("skybake: " + (dir.path() / "q.csv").string() + ":4: the object's altitude", 0), 0u) << err;
  ASSERT_EQ(
      RunCommand(Skybake() + " eval " + ShellQuote(set) + " --clamp --in " + ShellQuote(dir.path() / "q.csv"), dir, &out, &err),
      0)
      << err;
  EXPECT_TRUE(Contains(err, "q.csv:4:")) << err;
  EXPECT_TRUE(Contains(err, "clamped to")) << err;
  // The object now sits where the view leaves 2 km: d = -r mu + sqrt(r^2 mu^2 - r^2 + (R + 2 km)^2).
  const double R = 6360e3, r = R + 100.0, mu = 0.5, top = R + 2000.0;
  const double expected = -r * mu + std::sqrt(r * r * mu * mu - r * r + top * top);
  const std::vector<std::string> lines = testing::Lines(out);
  ASSERT_EQ(lines.size(), 3u) << out;
  EXPECT_EQ(lines[2].rfind("100,60,30,0,", 0), 0u) << lines[2];
  EXPECT_TRUE(Contains(err, std::to_string(static_cast<long>(expected)).substr(0, 4))) << err << " " << expected;
}

TEST(NewcomerDefects, D07_UnknownCommandsAndOptionsAreNamed) {
  TempDir dir;
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bkae earth", dir, nullptr, &err), 1);
  EXPECT_TRUE(Contains(err, "unknown command 'bkae'")) << err;
  EXPECT_EQ(RunCommand(Skybake() + " -V", dir, nullptr, &err), 1);
  EXPECT_TRUE(Contains(err, "unknown option '-V'")) << err;
  EXPECT_EQ(RunCommand(Skybake() + " --help", dir), 0);
  EXPECT_EQ(RunCommand(Skybake() + " --version", dir), 0);
}

TEST(NewcomerDefects, D08_ExitCodesFollowTheDocumentedScheme) {
  TempDir dir;
  std::string out, err;
  // A missing file is an I/O error, whichever kind of file.
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "a") + " --scene nope.toml", dir), 3);
  EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(dir.path()) + " --in nope.csv", dir), 3);
  EXPECT_EQ(RunCommand(Skybake() + " validate nope.toml", dir), 3);
  // A bad option value is a usage error, whichever option.
  for (const char* bad : {" --scattering-size 0 32 8 4", " --orders -3", " --orders abc", " --ray-samples 0",
                          " --format foo", " --sphere-samples 5000"}) {
    EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "a") + bad, dir, nullptr, &err), 1)
        << bad << ": " << err;
  }
  // An absurd size is refused before anything is allocated, naming the memory it needs.
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "a") + " --scattering-size 4096 4096 512 64",
                       dir, nullptr, &err),
            1);
  EXPECT_TRUE(Contains(err, "GiB")) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "a"));  // and no empty output folder
  // The documented codes include the interrupt.
  EXPECT_EQ(RunCommand(Skybake() + " --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "130 interrupted")) << out;
}

TEST(NewcomerDefects, D08_AnInterruptedBakeLeavesNoFolder) {
  TempDir dir;
  const fs::path out = dir.path() / "interrupted";
  std::string err;
  // The default earth bake takes about two seconds: SIGINT lands mid-bake,
  // once the first phase has finished (so the handler is in place).
  const fs::path log = dir.path() / "bake.log";
  const int code = RunCommand("(" + Skybake() + " bake earth -o " + ShellQuote(out) + " 2>" + ShellQuote(log) +
                                  " & pid=$!; while ! grep -q transmittance " + ShellQuote(log) +
                                  "; do sleep 0.05; done; kill -INT $pid; wait $pid; code=$?; cat " + ShellQuote(log) +
                                  " >&2; exit $code)",
                              dir, nullptr, &err);
  EXPECT_EQ(code, 130) << err;
  EXPECT_TRUE(Contains(err, "interrupted by SIGINT")) << err;
  EXPECT_FALSE(fs::exists(out));
}

TEST(NewcomerDefects, D09_StressHelpStatesItsOwnDefaultsOnce) {
  TempDir dir;
  std::string out;
  ASSERT_EQ(RunCommand(Skybake() + " stress --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "default 8 32 8 4")) << out;
  EXPECT_FALSE(Contains(out, "32 128 32 8")) << out;
  ASSERT_EQ(RunCommand(Skybake() + " bake --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "default 32 128 32 8")) << out;
}

TEST(NewcomerDefects, D11_BenchSaysOneRunAndConvertSummarisesOnStderr) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " bench earth --runs 1 --scattering-size 8 32 8 4", dir, &out, &err), 0) << err;
  EXPECT_FALSE(Contains(out, "median of 1 runs")) << out;
  EXPECT_TRUE(Contains(out, "one run")) << out;

  ASSERT_EQ(RunCommand(Skybake() + " bake earth --format exr -o " + ShellQuote(dir.path() / "set") + kSmall, dir), 0);
  ASSERT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(dir.path() / "set" / "irradiance.exr") + " " +
                           ShellQuote(dir.path() / "i.ktx2"),
                       dir, &out, &err),
            0);
  EXPECT_EQ(out, "");
  EXPECT_TRUE(Contains(err, "lossless")) << err;
}

TEST(NewcomerDefects, D11_DashReadsStandardInput) {
  TempDir dir;
  std::string out, err;
  const std::string mars = Examples("atmospheres/mars.toml");
  ASSERT_EQ(RunCommand(Skybake() + " validate - --json < " + mars, dir, &out, &err), 0) << err;
  EXPECT_EQ(nlohmann::json::parse(out)["name"], "mars");
  ASSERT_EQ(RunCommand(Skybake() + " bake - -o " + ShellQuote(dir.path() / "set") + kSmall + " < " + mars, dir, nullptr,
                       &err),
            0)
      << err;
  WriteText(dir.path() / "q.csv", "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,45,30,0\n");
  ASSERT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(dir.path() / "set") + " --in - --out - < " +
                           ShellQuote(dir.path() / "q.csv"),
                       dir, &out, &err),
            0)
      << err;
  EXPECT_EQ(testing::Lines(out).size(), 2u) << out;
  // A malformed standard input is named as such.
  EXPECT_EQ(RunCommand("echo 'name = ' | " + Skybake() + " validate -", dir, nullptr, &err), 2);
  EXPECT_EQ(err.rfind("skybake: standard input:1:", 0), 0u) << err;
}

// ---- the pipeline features ----

TEST(NewcomerPipeline, BatchBakesEachAtmosphereIntoItsOwnFolder) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth " + Examples("atmospheres/mars.toml") + " -o " +
                           ShellQuote(dir.path() / "out") + kSmall + " --format ktx2",
                       dir, nullptr, &err),
            0)
      << err;
  for (const char* name : {"earth", "mars"}) {
    EXPECT_TRUE(fs::exists(dir.path() / "out" / name / "skybake.json")) << name;
  }
  // A pattern, one failure among successes: the others are baked, the exit
  // code is the failure's, and --json reports each.
  ASSERT_EQ(RunCommand(Skybake() + " bake earth nope.toml light-fog -o " + ShellQuote(dir.path() / "p/{name}-lut") +
                           kSmall + " --format ktx2 --json",
                       dir, &out, &err),
            3);
  EXPECT_TRUE(fs::exists(dir.path() / "p/earth-lut/skybake.json"));
  EXPECT_TRUE(fs::exists(dir.path() / "p/light-fog-lut/skybake.json"));
  EXPECT_FALSE(fs::exists(dir.path() / "p/nope-lut"));
  const nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_EQ(report["bakes"].size(), 3u);
  EXPECT_EQ(report["failed"], 1);
  EXPECT_EQ(report["bakes"][1]["error"]["exit_code"], 3);
  EXPECT_EQ(report["bakes"][2]["atmosphere"], "light-fog");
  EXPECT_TRUE(Contains(err, "baked 2 of 3 atmospheres")) << err;
  // Two atmospheres into one folder is refused up front.
  EXPECT_EQ(RunCommand(Skybake() + " bake earth preset:earth -o " + ShellQuote(dir.path() / "q") + kSmall, dir), 1);
}

TEST(NewcomerPipeline, StressChecksAUsersOwnAtmosphere) {
  TempDir dir;
  std::string out, err;
  WriteText(dir.path() / "hazy.toml", ReadText(fs::path(SKYBAKE_SOURCE_DIR) / "examples/atmospheres/heavy-haze.toml"));
  ASSERT_EQ(RunCommand(Skybake() + " stress " + ShellQuote(dir.path() / "hazy.toml") + " --queries 2000 --json", dir, &out,
                       &err),
            0)
      << err;
  const nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_EQ(report.size(), 1u);
  EXPECT_EQ(report[0]["violations"], 0);
  EXPECT_GT(report[0]["values_checked"].get<long long>(), 2000);
}

TEST(NewcomerPipeline, JsonErrorsCarryTheCodeMessageAndLocation) {
  TempDir dir;
  std::string out, err;
  WriteText(dir.path() / "bad.toml",
            ReadText(fs::path(SKYBAKE_SOURCE_DIR) / "examples/atmospheres/mars.toml") + "\n[sun]\nx = 1\n");
  // A duplicate table: a TOML syntax error, with its line.
  EXPECT_EQ(RunCommand(Skybake() + " validate " + ShellQuote(dir.path() / "bad.toml") + " --json", dir, &out, &err), 2);
  nlohmann::json e = nlohmann::json::parse(out).at("error");
  EXPECT_EQ(e["exit_code"], 2);
  EXPECT_EQ(e["file"], (dir.path() / "bad.toml").string());  // the path as given
  EXPECT_GT(e["line"].get<int>(), 1);
  EXPECT_EQ("skybake: " + e["message"].get<std::string>() + "\n", err);
  // A bad value names its key.
  WriteText(dir.path() / "neg.toml", "name = \"x\"\n[planet]\nground_radius_km = -1\n");
  EXPECT_EQ(RunCommand(Skybake() + " validate " + ShellQuote(dir.path() / "neg.toml") + " --json", dir, &out, &err), 2);
  e = nlohmann::json::parse(out).at("error");
  EXPECT_EQ(e["file"], (dir.path() / "neg.toml").string());
  EXPECT_FALSE(e["key"].is_null()) << e;
  // Usage errors too.
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o x --orders abc --json", dir, &out), 1);
  EXPECT_EQ(nlohmann::json::parse(out)["error"]["exit_code"], 1);
}

}  // namespace
}  // namespace skybake
