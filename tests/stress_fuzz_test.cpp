// Bad input never crashes, hangs or leaks a NaN: mutated atmosphere files
// (byte flips, deleted, duplicated and swapped lines, NaN, +-inf, 1e308, -0,
// huge arrays, truncation) and mutated query CSVs, from a fixed seed.
//
// Every mutant goes through the code the commands run (ParseAtmosphere as
// `validate` does, a tiny Bake as `bake` does, ParseQueryCsv and the twin as
// `eval` does): it must be accepted or rejected with a skybake::Error on one
// line, and what is accepted must bake and evaluate to finite, non-negative
// values. A deterministic subset also goes to the skybake executable under
// `timeout`: no signal, no hang over 10 s, exit 0, 1 or 2 with one line on
// stderr. Not all of them: each run of the executable costs ~0.2 s of CPU
// before main (loading and relocating 275 shared libraries), so a thousand
// would take minutes on a shared 2-core machine; 72 runs take ~30 s alone
// and ~80 s beside the rest of the suite.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bake/config.h"
#include "bake/invariants.h"
#include "bake/stress_set.h"
#include "core/errors.h"
#include "formats/query_csv.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/twin.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

constexpr std::uint64_t kSeed = 20261123;
constexpr int kConfigMutants = 1200;
constexpr int kCsvMutants = 1000;
constexpr double kHangSeconds = 10.0;

// The smallest tables the settings allow, for mutants that parse.
BakeSettings TinySettings() {
  BakeSettings s;
  s.transmittance_width = 16, s.transmittance_height = 8;
  s.irradiance_width = 8, s.irradiance_height = 4;
  s.scattering_r_size = 4, s.scattering_mu_size = 8, s.scattering_mu_s_size = 4, s.scattering_nu_size = 2;
  s.ray_samples = 8, s.sphere_samples = 4, s.orders = 2;
  return s;
}
const char* kTinyBakeOptions =
    " --transmittance-size 16 8 --irradiance-size 8 4 --scattering-size 4 8 4 2 --ray-samples 8"
    " --sphere-samples 4 --orders 2 --format exr -q";

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed) : engine_(seed) {}

  std::size_t Below(std::size_t n) { return n == 0 ? 0 : engine_() % n; }

  // One random mutation of `text`; a few are applied in a row.
  std::string Mutate(std::string text) {
    static const char* kNumbers[] = {"nan", "+nan", "-nan", "inf", "+inf", "-inf", "1e308", "-1e308", "1e400",
                                     "-0", "-0.0", "0", "1e-320", "4.9e-324", "9223372036854775808", "-1"};
    std::vector<std::string> lines = Lines(text);
    switch (Below(9)) {
      case 0: {  // flip a bit
        if (text.empty()) return text;
        text[Below(text.size())] ^= static_cast<char>(1u << Below(8));
        return text;
      }
      case 1: {  // overwrite a byte
        if (text.empty()) return text;
        text[Below(text.size())] = static_cast<char>(Below(256));
        return text;
      }
      case 2:  // delete a line (often a key)
        if (!lines.empty()) lines.erase(lines.begin() + Below(lines.size()));
        break;
      case 3: {  // duplicate a line (often a key)
        if (lines.empty()) return text;
        std::size_t i = Below(lines.size());
        lines.insert(lines.begin() + i, lines[i]);
        break;
      }
      case 4:  // swap two lines
        if (lines.size() > 1) std::swap(lines[Below(lines.size())], lines[Below(lines.size())]);
        break;
      case 5:
      case 6: {  // replace a number with an extreme or special value
        std::vector<std::size_t> starts;
        for (std::size_t i = 0; i < text.size(); ++i) {
          bool digit = std::isdigit(static_cast<unsigned char>(text[i]));
          bool after_number = i > 0 && (std::isalnum(static_cast<unsigned char>(text[i - 1])) || text[i - 1] == '.' ||
                                        text[i - 1] == '-' || text[i - 1] == '+');
          if (digit && !after_number) starts.push_back(i);
        }
        if (starts.empty()) return text;
        std::size_t start = starts[Below(starts.size())], end = start;
        while (end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '.' ||
                                     ((text[end] == '-' || text[end] == '+') && (text[end - 1] == 'e' || text[end - 1] == 'E')))) {
          ++end;
        }
        return text.substr(0, start) + kNumbers[Below(std::size(kNumbers))] + text.substr(end);
      }
      case 7: {  // a huge array in place of a number
        std::size_t digit = text.find_first_of("0123456789", Below(text.size()));
        if (digit == std::string::npos) return text;
        std::string huge = "[";
        for (int i = 0; i < 100000; ++i) huge += i ? ",1.5" : "1.5";
        return text.substr(0, digit) + huge + "]" + text.substr(digit + 1);
      }
      case 8:  // truncate
        return text.substr(0, Below(text.size() + 1));
    }
    std::string joined;
    for (const std::string& line : lines) joined += line + "\n";
    return joined;
  }

  std::string MutateSome(const std::string& text) {
    std::string result = Mutate(text);
    for (std::size_t extra = Below(3); extra > 0; --extra) result = Mutate(result);
    return result;
  }

 private:
  std::mt19937_64 engine_;
};

bool OneLine(const std::string& message) {
  return !message.empty() && message.find('\n') == std::string::npos && message.find('\r') == std::string::npos;
}

// Seeds: the presets and the stress set, as files.
std::vector<std::string> ConfigSeeds() {
  std::vector<std::string> seeds;
  for (const fs::path& file : fs::directory_iterator(fs::path(SKYBAKE_SOURCE_DIR) / "examples" / "atmospheres")) {
    if (file.extension() == ".toml") seeds.push_back(testing::ReadText(file));
  }
  for (const StressAtmosphere& s : StressSet()) seeds.push_back(ToToml(s.atmosphere));
  return seeds;
}

const char* kCsvSeed =
    "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,distance_m,normal_zenith_deg,group\n"
    "0,45,30,0,,0,daylight\n"
    "1000,90,95,180,20000,90,twilight\n"
    "100000,120,60,45,,,space\n"
    "10,89.9,0,10,1500,30,horizon\n";

std::string Seconds(std::chrono::steady_clock::time_point start) {
  return std::to_string(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()) + " s";
}

TEST(Fuzz, MutatedAtmosphereFilesAreAcceptedOrRejectedCleanly) {
  const std::vector<std::string> seeds = ConfigSeeds();
  Mutator mutator(kSeed);
  int accepted = 0, rejected = 0, baked = 0;
  for (int i = 0; i < kConfigMutants; ++i) {
    const std::string text = mutator.MutateSome(seeds[i % seeds.size()]);
    SCOPED_TRACE("mutant " + std::to_string(i));
    auto start = std::chrono::steady_clock::now();
    try {
      Atmosphere atmosphere = ParseAtmosphere(text, "mutant.toml");
      ++accepted;
      // What validates must bake to finite, non-negative tables; a tenth of
      // them are baked (tiny tables), enough to cover every seed.
      if (i % 10 == 0) {
        BakeReport report;
        LutSet luts = Bake(atmosphere, TinySettings(), &report);
        InvariantReport r = CheckTableInvariants(luts, report);
        EXPECT_EQ(r.violations, 0) << (r.examples.empty() ? "" : r.examples[0]) << "\n" << text.substr(0, 2000);
        ++baked;
      }
    } catch (const Error& e) {
      ++rejected;
      EXPECT_EQ(e.code(), ExitCode::kInvalidInput) << e.what();
      EXPECT_TRUE(OneLine(e.what())) << e.what();
    }
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), kHangSeconds)
        << Seconds(start);
  }
  std::printf("%d mutants: %d accepted (%d baked), %d rejected\n", kConfigMutants, accepted, baked, rejected);
  EXPECT_GT(rejected, kConfigMutants / 4);  // the mutations do reach the validator
}

// Rows the random mutations rarely build whole, each once: extreme lengths
// (NaN before they were bounded), lengths below the positions' rounding
// (NaN before GetSkyRadianceToPoint checked for them), extreme angles.
const char* kExtremeRows[] = {
    "1e308,180,30,0,,0,x",  "1e200,180,30,0,,90,x", "100,90,30,1e308,1e308,0,x", "1e12,180,30,0,1e12,0,x",
    "1000,0,30,0,1e-12,0,x", "0,180,30,0,1e-320,0,x", "-1e308,0,30,0,1,0,x",     "-0,-0,-0,-0,-0,-0,x",
    "0,180,180,-1e308,0,180,x", "6e4,90,0,0,1e7,0,x",
};

TEST(Fuzz, MutatedQueryFilesAreAcceptedOrRejectedCleanly) {
  LutSet luts = Bake(testing::Earth(), TinySettings());
  Twin twin(MakeTwinTables(luts));
  Mutator mutator(kSeed + 1);
  const std::string header = kCsvSeed;
  int accepted = 0, rejected = 0;
  for (int i = 0; i < kCsvMutants + int(std::size(kExtremeRows)); ++i) {
    const std::string text = i < kCsvMutants ? mutator.MutateSome(kCsvSeed)
                                             : header.substr(0, header.find('\n') + 1) + kExtremeRows[i - kCsvMutants] + "\n";
    SCOPED_TRACE("mutant " + std::to_string(i) + ":\n" + text.substr(0, 1000));
    try {
      QueryTable table = ParseQueryCsv(text, "mutant.csv");
      ++accepted;
      for (const Query& q : table.queries) {
        QueryGeometry g = MakeQueryGeometry(q, luts.parameters.bottom_radius);
        glsl::vec3 transmittance, sky;
        glsl::vec3 radiance = q.distance_m > 0.0
            ? twin.SkyRadianceToPoint(g.camera, g.camera + g.view * q.distance_m, g.sun, &transmittance)
            : twin.SkyRadiance(g.camera, g.view, g.sun, &transmittance);
        glsl::vec3 sun = twin.SunAndSkyIrradiance(g.camera, g.normal, g.sun, &sky);
        for (int c = 0; c < 3; ++c) {
          for (double v : {radiance[c], transmittance[c], sun[c], sky[c]}) {
            ASSERT_TRUE(std::isfinite(v) && v >= 0.0)
                << "altitude " << q.altitude_m << " distance " << q.distance_m << " gives " << v;
          }
        }
      }
    } catch (const Error& e) {
      ++rejected;
      EXPECT_EQ(e.code(), ExitCode::kInvalidInput) << e.what();
      EXPECT_TRUE(OneLine(e.what())) << e.what();
    }
  }
  std::printf("%d files: %d accepted, %d rejected\n", accepted + rejected, accepted, rejected);
  EXPECT_GT(rejected, kCsvMutants / 4);
}

// The executable itself on a deterministic subset: exit 0, 1 or 2, one line
// on stderr when it fails, no signal, no hang.
void ExpectCleanExit(const std::string& command, const TempDir& dir, const std::string& what) {
  std::string err;
  int code = RunCommand("timeout -s KILL " + std::to_string(int(kHangSeconds)) + " " + command, dir, nullptr, &err);
  EXPECT_TRUE(code == 0 || code == 1 || code == 2) << what << ": exit " << code
                                                   << (code == 137 ? " (killed: hang over 10 s)" : "") << "\n" << err;
  if (code != 0) {
    EXPECT_EQ(Lines(err).size(), 1u) << what << ": " << err;
  }
}

TEST(Fuzz, ExecutableHandlesMutatedFiles) {
  TempDir dir;
  const fs::path config = dir.path() / "mutant.toml", queries = dir.path() / "mutant.csv";
  const fs::path luts = dir.path() / "luts";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(luts) + kTinyBakeOptions, dir), 0);
  const std::vector<std::string> seeds = ConfigSeeds();
  Mutator mutator(kSeed + 2);
  for (int i = 0; i < 36; ++i) {
    testing::WriteText(config, mutator.MutateSome(seeds[i % seeds.size()]));
    ExpectCleanExit(Skybake() + " validate " + ShellQuote(config), dir, "validate mutant " + std::to_string(i));
    if (i % 3 == 0) {
      ExpectCleanExit(Skybake() + " bake " + ShellQuote(config) + " -o " + ShellQuote(dir.path() / "out") +
                          kTinyBakeOptions,
                      dir, "bake mutant " + std::to_string(i));
    }
  }
  for (int i = 0; i < 24; ++i) {
    testing::WriteText(queries, mutator.MutateSome(kCsvSeed));
    ExpectCleanExit(Skybake() + " eval " + ShellQuote(luts) + " --in " + ShellQuote(queries) + " --out " +
                        ShellQuote(dir.path() / "results.csv"),
                    dir, "eval mutant " + std::to_string(i));
  }
}

}  // namespace
}  // namespace skybake
