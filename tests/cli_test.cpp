// The skybake executable end to end: bake, eval, exit codes and one-line
// errors, atomic outputs.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;
using testing::WriteText;

const char* kSmallBake =
    " --transmittance-size 64 16 --irradiance-size 16 4 --scattering-size 8 32 8 4 --ray-samples 32"
    " --sphere-samples 8 --orders 2";

TEST(CliBake, HelpAndVersion) {
  TempDir dir;
  std::string out;
  EXPECT_EQ(RunCommand(Skybake() + " --help", dir, &out), 0);
  EXPECT_NE(out.find("Exit codes"), std::string::npos);
  for (const char* command : {"bake", "eval", "validate", "presets"}) {
    EXPECT_EQ(RunCommand(Skybake() + " " + command + " --help", dir, &out), 0) << command;
  }
  EXPECT_EQ(RunCommand(Skybake() + " --version", dir, &out), 0);
  EXPECT_NE(out.find("skybake "), std::string::npos);
  EXPECT_EQ(RunCommand(Skybake() + " bake", dir), 1);             // missing arguments
  EXPECT_EQ(RunCommand(Skybake() + " bake earth --bogus", dir), 1);  // unknown option
}

TEST(CliBake, BakeWritesTablesAndManifestWithJsonReport) {
  TempDir dir;
  std::string out, err;
  fs::path lut = dir.path() / "earth";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(lut) + kSmallBake + " --json", dir, &out, &err), 0)
      << err;
  nlohmann::json report = nlohmann::json::parse(out);
  EXPECT_EQ(report["orders"], 2);
  EXPECT_GE(report["timings"].size(), 5u);
  EXPECT_NE(err.find("single scattering"), std::string::npos);  // per-phase timings on stderr
  for (const char* file : {"transmittance.exr", "irradiance.exr", "scattering.exr", "single_mie_scattering.exr",
                           "skybake.json"}) {
    EXPECT_TRUE(fs::exists(lut / file)) << file;
  }
  // No temporary files left behind.
  for (const auto& entry : fs::directory_iterator(lut)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  nlohmann::json manifest = nlohmann::json::parse(testing::ReadText(lut / "skybake.json"));
  EXPECT_EQ(manifest["parameters"]["scattering_mu_size"], 32);
  EXPECT_NE(manifest["command"].get<std::string>().find("bake earth"), std::string::npos);
}

// --preview starts from PreviewBakeSettings(); a size or sample option given
// beside it replaces that value only.
TEST(CliBake, PreviewTakesItsSettingsWhereNoOptionIsGiven) {
  TempDir dir;
  fs::path lut = dir.path() / "earth";
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -q --format exr --runtime none --preview --ray-samples 48 "
                                   "--scattering-size 16 64 16 8 -o " + ShellQuote(lut),
                       dir, nullptr, &err),
            0)
      << err;
  const nlohmann::json manifest = nlohmann::json::parse(testing::ReadText(lut / "skybake.json"));
  const BakeSettings preview = PreviewBakeSettings();
  EXPECT_EQ(manifest["bake"]["ray_samples"], 48);
  EXPECT_EQ(manifest["bake"]["sphere_samples"], preview.sphere_samples);
  EXPECT_EQ(manifest["bake"]["transmittance_samples"], preview.transmittance_samples);
  EXPECT_NE(preview.sphere_samples, BakeSettings().sphere_samples);
  EXPECT_EQ(manifest["parameters"]["scattering_nu_size"], 8);
  EXPECT_EQ(manifest["parameters"]["scattering_mu_s_size"], preview.scattering_mu_s_size);
  EXPECT_EQ(manifest["parameters"]["transmittance_width"], preview.transmittance_width);
}

TEST(CliBake, BakeIsReproducible) {
  TempDir dir;
  fs::path a = dir.path() / "a", b = dir.path() / "b";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(a) + kSmallBake + " --threads 1", dir), 0);
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(b) + kSmallBake + " --threads 2", dir), 0);
  for (const char* file : {"transmittance.exr", "irradiance.exr", "scattering.exr", "single_mie_scattering.exr"}) {
    EXPECT_TRUE(testing::ReadText(a / file) == testing::ReadText(b / file)) << file;
  }
}

TEST(CliBake, BakeErrors) {
  TempDir dir;
  std::string err;
  // A file where the output directory should be: I/O error, one line.
  WriteText(dir.path() / "file", "x");
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "file" / "sub") + kSmallBake, dir,
                       nullptr, &err), 3);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
  // Out-of-range option values: usage errors; a missing atmosphere: an I/O error.
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + " --scattering-size 8 31 8 4",
                       dir, nullptr, &err), 1);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
  EXPECT_EQ(RunCommand(Skybake() + " bake no-such-atmosphere -o " + ShellQuote(dir.path() / "x"), dir), 3);
  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + " --orders -1", dir), 1);
  // A supercompression that is not none, zstd or zstd:1..22: a usage error
  // naming the option, before anything is baked or written.
  for (const char* value : {"zstd:0", "zstd:23", "zstd:", "zlib", "zstd:3x"}) {
    EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "y") +
                             " --ktx2-supercompression " + value + kSmallBake,
                         dir, nullptr, &err),
              1)
        << value;
    EXPECT_EQ(Lines(err).size(), 1u) << err;
    EXPECT_NE(err.find("--ktx2-supercompression"), std::string::npos) << err;
  }
  // A spectral bake's higher orders are interpolated or exact, and only a
  // spectral bake has them: usage errors naming the option.
  for (const char* options : {" --wavelengths 6 --spectral-higher-orders fast", " --spectral-higher-orders exact"}) {
    EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "y") + options + kSmallBake, dir,
                         nullptr, &err),
              1)
        << options;
    EXPECT_EQ(Lines(err).size(), 1u) << err;
    EXPECT_NE(err.find("--spectral-higher-orders"), std::string::npos) << err;
  }
  EXPECT_FALSE(fs::exists(dir.path() / "y"));
}

class EvalTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(Lut()) + kSmallBake, *dir_), 0);
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path Lut() { return dir_->path() / "earth"; }
  static TempDir* dir_;
};
TempDir* EvalTest::dir_ = nullptr;

TEST_F(EvalTest, AnswersQueriesWithDocumentedColumns) {
  TempDir dir;
  WriteText(dir.path() / "q.csv",
            "sun_zenith_deg,altitude_m,view_zenith_deg,view_sun_azimuth_deg,distance_m,normal_zenith_deg\n"
            "30,0,0,0,,0\n"         // zenith sky at noon-ish
            "30,1000,120,0,,\n"     // looking at the ground from 1 km
            "30,500e3,160,0,,\n"    // from space, ray through the atmosphere
            "30,500e3,0,0,,\n"      // from space, looking away
            "30,0,89,0,10000,\n");  // aerial perspective over 10 km
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(Lut()) + " --in " + ShellQuote(dir.path() / "q.csv") +
                           " --out " + ShellQuote(dir.path() / "r.csv"),
                       dir, nullptr, &err), 0)
      << err;
  std::vector<std::string> lines = Lines(testing::ReadText(dir.path() / "r.csv"));
  ASSERT_EQ(lines.size(), 6u);
  EXPECT_EQ(lines[0],
            "sun_zenith_deg,altitude_m,view_zenith_deg,view_sun_azimuth_deg,distance_m,normal_zenith_deg,"
            "radiance_680nm,radiance_550nm,radiance_440nm,transmittance_680nm,transmittance_550nm,"
            "transmittance_440nm,sun_irradiance_680nm,sun_irradiance_550nm,sun_irradiance_440nm,"
            "sky_irradiance_680nm,sky_irradiance_550nm,sky_irradiance_440nm");
  auto values = [&](int row) {
    std::vector<double> v;
    std::stringstream in(lines[row]);
    for (std::string field; std::getline(in, field, ',');) v.push_back(field.empty() ? -1.0 : std::stod(field));
    return v;
  };
  std::vector<double> zenith = values(1), ground = values(2), space_hit = values(3), space_miss = values(4),
                      aerial = values(5);
  // Zenith sky: blue brighter than red, transmittance between 0 and 1.
  EXPECT_GT(zenith[8], zenith[6]);
  for (int c = 9; c < 12; ++c) {
    EXPECT_GT(zenith[c], 0.5);
    EXPECT_LT(zenith[c], 1.0);
  }
  // Sun irradiance on a horizontal surface: E0 * T * cos(30 deg), T < 1.
  EXPECT_LT(zenith[12], 1.474 * std::cos(30.0 * M_PI / 180.0));
  EXPECT_GT(zenith[12], 0.5 * 1.474 * std::cos(30.0 * M_PI / 180.0));
  EXPECT_GT(zenith[17], 0.0);
  // Looking at the ground: transmittance 0, some in-scattered light.
  for (int c = 9; c < 12; ++c) EXPECT_EQ(ground[c], 0.0);
  EXPECT_GT(ground[6], 0.0);
  // From space: a ray through the atmosphere sees light; one that misses gets 0 and T = 1.
  EXPECT_GT(space_hit[8], 0.0);
  for (int c = 6; c < 9; ++c) EXPECT_EQ(space_miss[c], 0.0);
  for (int c = 9; c < 12; ++c) EXPECT_EQ(space_miss[c], 1.0);
  // Aerial perspective over 10 km: less light and more transmittance than the whole ray.
  for (int c = 9; c < 12; ++c) {
    EXPECT_GT(aerial[c], 0.3);
    EXPECT_LT(aerial[c], 1.0);
  }
}

TEST_F(EvalTest, MalformedRowIsAnErrorNamingTheLineAndWritesNothing) {
  TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,0,0\n0,abc,0,0\n", "q.csv:3"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,0,0\n0,0,0\n", "q.csv:3"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\nnan,0,0,0\n", "q.csv:2"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,190,0,0\n", "q.csv:2"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,distance_m\n0,0,0,0,-5\n", "q.csv:2"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg\n0,0,0\n", "view_sun_azimuth_deg"},
      {"altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,colour\n0,0,0,0,1\n", "colour"},
      {"", "empty"},
  };
  for (const auto& [csv, expected] : cases) {
    WriteText(dir.path() / "q.csv", csv);
    std::string err;
    EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(Lut()) + " --in " + ShellQuote(dir.path() / "q.csv") +
                             " --out " + ShellQuote(dir.path() / "r.csv"),
                         dir, nullptr, &err), 2)
        << csv;
    EXPECT_EQ(Lines(err).size(), 1u) << err;
    EXPECT_NE(err.find(expected), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(dir.path() / "r.csv"));
  }
  // A directory that holds no baked set: I/O error.
  WriteText(dir.path() / "q.csv", "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,0,0\n");
  EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(dir.path()) + " --in " + ShellQuote(dir.path() / "q.csv"), dir),
            3);
}

}  // namespace
}  // namespace skybake
