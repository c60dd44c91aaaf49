// The presets, LoadAtmosphere (file, then preset, then error) and the
// `presets` / `validate` commands.
#include "bake/config.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/constants.h"
#include "core/errors.h"
#include "config_test_util.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Presets

TEST(Presets, ListsAllSeven) {
  std::set<std::string> names;
  for (const PresetInfo& preset : ListPresets()) {
    names.insert(preset.name);
    EXPECT_FALSE(preset.description.empty()) << preset.name;
  }
  EXPECT_EQ(names, kPresetNames);
}

TEST(Presets, FilesNameThemselvesAndMatchTheBuiltInCopy) {
  int count = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kPresetDir)) {
    if (entry.path().extension() != ".toml") continue;
    std::string stem = entry.path().stem().string();
    SCOPED_TRACE(stem);
    Atmosphere from_file = LoadAtmosphere(entry.path().string());
    EXPECT_EQ(from_file.name, stem);
    EXPECT_FALSE(from_file.description.empty());
    ExpectIdentical(from_file, LoadPreset(stem));
    ++count;
  }
  EXPECT_EQ(count, static_cast<int>(kPresetNames.size()));
}

TEST(Presets, ToTomlRoundTripsEveryPreset) {
  for (const std::string& name : kPresetNames) {
    SCOPED_TRACE(name);
    Atmosphere preset = LoadPreset(name);
    std::string text = ToToml(preset);
    Atmosphere reparsed = ParseAtmosphere(text, name + ".resolved.toml");
    ExpectIdentical(reparsed, preset);
    EXPECT_EQ(ToToml(reparsed), text);  // canonical form is a fixed point
  }
}

TEST(Presets, EarthHasBruneton2017Parameters) {
  Atmosphere earth = LoadPreset("earth");
  EXPECT_EQ(earth.bottom_radius_m, 6360e3);
  EXPECT_EQ(earth.top_radius_m, 6420e3);
  ExpectSpectrumEq(earth.ground_albedo, Spectrum(0.1), "albedo");
  ExpectSpectrumEq(earth.wavelengths_nm, Spectrum(680.0, 550.0, 440.0), "wavelengths");
  // The sun and ozone come from the published spectra (spectral_data_test
  // checks them); at these wavelengths they are Bruneton's values to the
  // digits he gives.
  const Spectrum sun(1.474, 1.8504, 1.91198);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(earth.solar_irradiance[i], sun[i], 5e-6 * sun[i]);
  EXPECT_EQ(earth.sun_angular_radius_rad, 0.004675);
  EXPECT_NEAR(earth.mu_s_min, -0.2079, 1e-4);
  ASSERT_EQ(earth.constituents.size(), 3u);

  const Constituent& rayleigh = Find(earth, "rayleigh");
  const double published[] = {5.802e-6, 13.558e-6, 33.100e-6};
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(rayleigh.scattering_per_m[i] / published[i], 1.0, 1e-3);
  ExpectSpectrumEq(rayleigh.absorption_per_m, Spectrum(0.0), "rayleigh absorption");
  EXPECT_EQ(rayleigh.phase.kind, PhaseKind::kRayleigh);
  EXPECT_NEAR(rayleigh.density.At(0.0), 1.0, 1e-15);
  EXPECT_NEAR(rayleigh.density.At(8000.0), std::exp(-1.0), 1e-15);

  const Constituent& mie = Find(earth, "mie");
  ExpectSpectrumEq(mie.scattering_per_m, Spectrum(3.996e-6), "mie scattering");
  ExpectSpectrumEq(mie.absorption_per_m, Spectrum(0.444e-6), "mie absorption");
  EXPECT_NEAR(mie.Extinction()[0], 4.44e-6, 1e-18);
  EXPECT_NEAR(mie.scattering_per_m[0] / mie.Extinction()[0], 0.9, 1e-12);
  EXPECT_EQ(mie.phase.kind, PhaseKind::kCornetteShanks);
  EXPECT_EQ(mie.phase.g, 0.8);
  EXPECT_NEAR(mie.density.At(1200.0), std::exp(-1.0), 1e-15);

  const Constituent& ozone = Find(earth, "ozone");
  ExpectSpectrumEq(ozone.scattering_per_m, Spectrum(0.0), "ozone scattering");
  const Spectrum bruneton_ozone(0.650e-6, 1.881e-6, 0.085e-6);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(ozone.absorption_per_m[i], bruneton_ozone[i], 5e-4 * bruneton_ozone[i]);
}

TEST(Presets, OzoneTentProfile) {
  // 0 at 10 km, 1 at 25 km, 0 at 40 km, linear in between, 0 outside.
  Atmosphere earth = LoadPreset("earth");
  const DensityProfile& ozone = Find(earth, "ozone").density;
  const std::map<double, double> expected = {
      {0.0, 0.0},      {5000.0, 0.0},  {10000.0, 0.0},  {17500.0, 0.5}, {25000.0, 1.0},
      {32500.0, 0.5},  {40000.0, 0.0}, {50000.0, 0.0},  {60000.0, 0.0}, {24999.0, 1.0 - 1.0 / 15000},
      {25001.0, 1.0 - 1.0 / 15000}};
  for (const auto& [altitude, density] : expected)
    EXPECT_NEAR(ozone.At(altitude), density, 1e-12) << altitude << " m";
  // The layer boundary and the corners where the clamp to [0, 1] bites.
  const std::vector<double> corners = {10000.0, 25000.0, 40000.0};
  std::vector<double> breakpoints = ozone.Breakpoints();
  ASSERT_EQ(breakpoints.size(), corners.size());
  for (size_t i = 0; i < corners.size(); ++i) EXPECT_NEAR(breakpoints[i], corners[i], 1e-6);
}

// A published aerosol: its scattering, its phase function and the altitude
// at which its exponential density has fallen to 1/e.
void ExpectAerosol(const Constituent& c, const Spectrum& scattering, PhaseKind phase, double g, double scale_height_m) {
  SCOPED_TRACE("constituent " + c.name);
  ExpectSpectrumEq(c.scattering_per_m, scattering, "scattering");
  EXPECT_EQ(c.phase.kind, phase);
  EXPECT_EQ(c.phase.g, g);
  EXPECT_NEAR(c.density.At(scale_height_m), std::exp(-1.0), 1e-15);
}

TEST(Presets, EarthClear2008HasBrunetonNeyretParameters) {
  Atmosphere clear = LoadPreset("earth-clear-2008");
  ASSERT_EQ(clear.constituents.size(), 2u);  // no ozone
  ExpectIdentical(Find(clear, "rayleigh"), Find(LoadPreset("earth"), "rayleigh"));
  const Constituent& mie = Find(clear, "mie");
  ExpectAerosol(mie, Spectrum(2e-5), PhaseKind::kCornetteShanks, 0.76, 1200.0);
  EXPECT_NEAR(mie.scattering_per_m[1] / mie.Extinction()[1], 0.9, 1e-12);
}

TEST(Presets, HazeAndFogFollowHoffmanPreetham) {
  struct Haze {
    std::string name;
    Spectrum scattering;
    double g;
  };
  const Haze table[] = {
      {"light-haze", {2e-5, 3e-5, 4e-5}, 0.75},
      {"heavy-haze", {8e-5, 1e-4, 1.2e-4}, 0.8},
      {"light-fog", {9e-4, 1e-3, 1.1e-3}, 0.85},
      {"heavy-fog", {1e-2, 1e-2, 1e-2}, 0.85},  // blue: the source's 1e-5 is a misprint
  };
  Atmosphere earth = LoadPreset("earth");
  for (const Haze& expected : table) {
    SCOPED_TRACE(expected.name);
    Atmosphere atmosphere = LoadPreset(expected.name);
    ASSERT_EQ(atmosphere.constituents.size(), 3u);
    // The air is earth's air without its aerosols.
    ExpectIdentical(Find(atmosphere, "rayleigh"), Find(earth, "rayleigh"));
    ExpectIdentical(Find(atmosphere, "ozone"), Find(earth, "ozone"));
    const Constituent& haze = Find(atmosphere, "haze");
    // Optical length 1.25 km.
    ExpectAerosol(haze, expected.scattering, PhaseKind::kHenyeyGreenstein, expected.g, 1250.0);
    ExpectSpectrumEq(haze.absorption_per_m, Spectrum(0.0), "haze absorption");
  }
}

TEST(Presets, MarsIsLitByTheSunAt1524AU) {
  Atmosphere mars = LoadPreset("mars");
  Atmosphere earth = LoadPreset("earth");
  EXPECT_EQ(mars.bottom_radius_m, 3389.5e3);
  EXPECT_EQ(mars.top_radius_m - mars.bottom_radius_m, 80e3);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(mars.solar_irradiance[i] / (earth.solar_irradiance[i] / (1.524 * 1.524)), 1.0, 1e-6);
    EXPECT_GE(mars.ground_albedo[i], 0.0);
  }
  EXPECT_NEAR(mars.sun_angular_radius_rad / (earth.sun_angular_radius_rad / 1.524), 1.0, 1e-6);

  const Constituent& gas = Find(mars, "gas");
  ExpectSpectrumEq(gas.scattering_per_m, Spectrum(19.918e-6, 13.57e-6, 5.75e-6), "gas");
  EXPECT_NEAR(gas.density.At(11000.0), std::exp(-1.0), 1e-15);
  const Constituent& dust = Find(mars, "dust");
  ExpectAerosol(dust, Spectrum(53.6e-6), PhaseKind::kHenyeyGreenstein, 0.85, 3100.0);
  EXPECT_NEAR(dust.scattering_per_m[0] / dust.Extinction()[0], 0.99, 1e-12);
}


// ---------------------------------------------------------------------------
// LoadAtmosphere

TEST(LoadAtmosphere, FileThenPresetThenError) {
  ExpectIdentical(LoadAtmosphere("mars"), LoadPreset("mars"));
  // A missing file is an I/O error; a bare word names it as a file or preset.
  EXPECT_THROW(LoadAtmosphere("no_such_atmosphere.toml"), IoError);
  try {
    LoadAtmosphere("no_such_atmosphere");
    ADD_FAILURE() << "no error";
  } catch (const IoError& e) {
    EXPECT_STREQ(e.what(), "no_such_atmosphere: no such file or preset (see skybake presets)");
  }
  EXPECT_NE(InputErrorOf([] { LoadPreset("venus"); }).find("venus: no such preset"),
            std::string::npos);
  EXPECT_THROW(LoadAtmosphere((kSourceDir / "tests" / "data").string()), IoError);

  // Errors name the file by the path it was given as, which finds it.
  fs::path path = WriteScratchFile("deep/er/custom.toml", "bogus = 1\n" + kMinimal);
  std::string message = InputErrorOf([&] { LoadAtmosphere(path.string()); });
  EXPECT_EQ(message.rfind(path.string() + ": bogus: unknown key", 0), 0u) << message;
}

// ---------------------------------------------------------------------------
// The `presets` and `validate` commands

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

CommandResult RunSkybake(const std::string& arguments) {
  static const testing::TempDir dir;
  CommandResult result;
  result.exit_code = testing::RunCommand(testing::Skybake() + " " + arguments, dir, &result.out, &result.err);
  return result;
}

int CountLines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(Cli, ValidateBadFileExitsTwoWithOneLine) {
  fs::path bad = kSourceDir / "tests/data/bad_configs/g_above_one.toml";
  CommandResult result = RunSkybake("validate '" + bad.string() + "'");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(CountLines(result.err), 1) << result.err;
  EXPECT_NE(result.err.find("g_above_one.toml: constituents.air.phase.g = 1.2 is outside (-1, 1)"),
            std::string::npos)
      << result.err;
  EXPECT_EQ(result.out, "");
}

TEST(Cli, ValidateMissingPathExitsThree) {
  CommandResult result = RunSkybake("validate does/not/exist.toml");
  EXPECT_EQ(result.exit_code, 3);  // a missing file is an I/O error
  EXPECT_EQ(CountLines(result.err), 1) << result.err;
  EXPECT_NE(result.err.find("does/not/exist.toml: no such file"), std::string::npos)
      << result.err;
}

TEST(Cli, PresetsListsAllSeven) {
  CommandResult result = RunSkybake("presets");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  std::set<std::string> listed;
  std::istringstream lines(result.out);
  for (std::string line; std::getline(lines, line);) listed.insert(line.substr(0, line.find(' ')));
  EXPECT_EQ(listed, kPresetNames);

  CommandResult json = RunSkybake("presets --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  EXPECT_EQ(nlohmann::json::parse(json.out).size(), kPresetNames.size());
}

TEST(Cli, ValidateOutputIsAValidFileOfTheSameAtmosphere) {
  CommandResult result = RunSkybake("validate earth");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.err, "");
  ExpectIdentical(ParseAtmosphere(result.out, "stdout"), LoadPreset("earth"));

  // Feeding the output back through the command reproduces it exactly.
  fs::path resolved = WriteScratchFile("earth.resolved.toml", result.out);
  CommandResult again = RunSkybake("validate '" + resolved.string() + "'");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(again.out, result.out);
}

TEST(Cli, ValidateJson) {
  CommandResult result = RunSkybake("validate mars --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  nlohmann::json json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json["name"], "mars");
  EXPECT_EQ(json["planet"]["top_radius_m"].get<double>(), 3469.5e3);
  EXPECT_EQ(json["constituents"]["dust"]["phase"]["g"].get<double>(), 0.85);
}

}  // namespace
}  // namespace skybake
