// Bakes in a pipeline, through the skybake executable: output folders an
// engine project can live in (PipelineDefects.D06_*: files skybake did not
// write never block a bake, and what does block one is refused before the
// bake).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

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

const char* kSmall =
    " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32"
    " --sphere-samples 8 --orders 2";

std::string Quoted(const fs::path& p) { return ShellQuote(p.string()); }

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct BakeRun {
  int exit_code = -1;
  json report;  // stdout's --json report; null unless it parses
  std::string err;
};

// `skybake bake ARGS --json`.
BakeRun Bake(const TempDir& dir, const std::string& args) {
  BakeRun run;
  std::string out;
  run.exit_code = RunCommand(Skybake() + " bake " + args + " --json", dir, &out, &run.err);
  run.report = json::parse(out, nullptr, /*allow_exceptions=*/false);
  return run;
}

// ---- issue 50, defect 6: output folders an engine project can live in ----

TEST(PipelineDefects, D06_FilesSkybakeDidNotWriteNeverBlockABake) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  fs::create_directories(out / "Editor");
  WriteText(out / "README.txt", "the sky tables of level 3");
  WriteText(out / "transmittance.ktx2.meta", "guid: 1234");
  // A folder holding only foreign files bakes (it used to bake, then exit 3).
  BakeRun first = Bake(dir, "earth -o " + Quoted(out) + kSmall);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // Re-bakes of other settings, with and without --clean, leave them too.
  BakeRun second = Bake(dir, "earth --transmittance-samples 32 -o " + Quoted(out) + kSmall);
  ASSERT_EQ(second.exit_code, 0) << second.err;
  BakeRun cleaned = Bake(dir, "earth --clean --format ktx2 -o " + Quoted(out) + kSmall);
  ASSERT_EQ(cleaned.exit_code, 0) << cleaned.err;
  EXPECT_FALSE(fs::exists(out / "transmittance.exr"));  // the earlier set's, removed by --clean
  EXPECT_EQ(ReadText(out / "README.txt"), "the sky tables of level 3");
  EXPECT_EQ(ReadText(out / "transmittance.ktx2.meta"), "guid: 1234");
  EXPECT_TRUE(fs::is_directory(out / "Editor"));
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + Quoted(out), dir, nullptr, &err), 0) << err;
}

TEST(PipelineDefects, D06_AnEarlierSetsTablesAreRefusedBeforeTheBake) {
  TempDir dir;
  const fs::path out = dir.path() / "sky";
  ASSERT_EQ(Bake(dir, "earth -q -o " + Quoted(out) + kSmall).exit_code, 0);
  const std::string manifest = ReadText(out / "skybake.json");
  // EXR only would leave the earlier set's KTX2 tables beside the new
  // manifest: refused with one line, and before anything is baked.
  std::string err;
  EXPECT_EQ(RunCommand(Skybake() + " bake earth --format exr -o " + Quoted(out) + kSmall, dir, nullptr, &err), 3);
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

}  // namespace
}  // namespace skybake
