// Atmosphere files, presets, validation and the `presets` / `validate` commands.
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
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;

const fs::path kSourceDir = SKYBAKE_SOURCE_DIR;
const fs::path kPresetDir = kSourceDir / "examples" / "atmospheres";
const std::set<std::string> kPresetNames = {"earth",      "earth-clear-2008", "light-haze",
                                            "heavy-haze", "light-fog",        "heavy-fog",
                                            "mars"};

using testing::ReadText;

const fs::path& ScratchDir() {
  static const testing::TempDir scratch;
  return scratch.path();
}

fs::path WriteScratchFile(const std::string& name, const std::string& text) {
  fs::path path = ScratchDir() / name;
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

std::string InputErrorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

void ExpectSpectrumEq(const Spectrum& a, const Spectrum& b, const std::string& what) {
  for (int i = 0; i < kWavelengthCount; ++i) EXPECT_EQ(a[i], b[i]) << what << "[" << i << "]";
}

void ExpectIdentical(const Constituent& a, const Constituent& b) {
  SCOPED_TRACE("constituent " + a.name);
  EXPECT_EQ(a.name, b.name);
  ExpectSpectrumEq(a.scattering_per_m, b.scattering_per_m, "scattering_per_m");
  ExpectSpectrumEq(a.absorption_per_m, b.absorption_per_m, "absorption_per_m");
  EXPECT_TRUE(a.phase == b.phase);
  EXPECT_EQ(a.density.kind, b.density.kind);
  ASSERT_EQ(a.density.layers.size(), b.density.layers.size());
  for (size_t i = 0; i < a.density.layers.size(); ++i) {
    const DensityLayer &la = a.density.layers[i], &lb = b.density.layers[i];
    EXPECT_EQ(la.width_m, lb.width_m) << "layer " << i;
    EXPECT_EQ(la.exp_term, lb.exp_term) << "layer " << i;
    EXPECT_EQ(la.exp_scale_per_m, lb.exp_scale_per_m) << "layer " << i;
    EXPECT_EQ(la.linear_term_per_m, lb.linear_term_per_m) << "layer " << i;
    EXPECT_EQ(la.constant_term, lb.constant_term) << "layer " << i;
  }
  EXPECT_EQ(a.density.altitudes_m, b.density.altitudes_m);
  EXPECT_EQ(a.density.densities, b.density.densities);
}

// Field-by-field, bit-exact equality.
void ExpectIdentical(const Atmosphere& a, const Atmosphere& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.bottom_radius_m, b.bottom_radius_m);
  EXPECT_EQ(a.top_radius_m, b.top_radius_m);
  ExpectSpectrumEq(a.ground_albedo, b.ground_albedo, "ground_albedo");
  ExpectSpectrumEq(a.wavelengths_nm, b.wavelengths_nm, "wavelengths_nm");
  ExpectSpectrumEq(a.solar_irradiance, b.solar_irradiance, "solar_irradiance");
  EXPECT_EQ(a.sun_angular_radius_rad, b.sun_angular_radius_rad);
  EXPECT_EQ(a.mu_s_min, b.mu_s_min);
  ASSERT_EQ(a.constituents.size(), b.constituents.size());
  for (size_t i = 0; i < a.constituents.size(); ++i)
    ExpectIdentical(a.constituents[i], b.constituents[i]);
}

const Constituent& Find(const Atmosphere& atmosphere, const std::string& name) {
  for (const Constituent& c : atmosphere.constituents) {
    if (c.name == name) return c;
  }
  throw std::runtime_error(atmosphere.name + " has no constituent " + name);
}

// A valid file without constituents; tests append to it.
const std::string kMinimal = R"(
name = "minimal"
[planet]
ground_radius_km = 6360.0
top_radius_km = 6420.0
ground_albedo = 0.1
[sun]
irradiance_w_m2_nm = 1.5
angular_radius_rad = 0.004675
lowest_zenith_deg = 102.0
)";

Atmosphere ParseMinimalWith(const std::string& extra) {
  return ParseAtmosphere(kMinimal + extra, "test.toml");
}

// ---------------------------------------------------------------------------
// Malformed files

TEST(BadConfigs, EachFailsWithOneLineNamingFileAndProblem) {
  std::vector<fs::path> files;
  for (const fs::directory_entry& entry : fs::directory_iterator(kSourceDir / "tests/data/bad_configs"))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  EXPECT_GE(files.size(), 25u);

  for (const fs::path& path : files) {
    std::string name = path.filename().string();
    SCOPED_TRACE(name);
    std::string text = ReadText(path);
    const std::string marker = "# expect: ";
    ASSERT_EQ(text.rfind(marker, 0), 0u) << "first line must be '# expect: <substring>'";
    std::string expected = text.substr(marker.size(), text.find('\n') - marker.size());
    ASSERT_FALSE(expected.empty());
    try {
      LoadAtmosphere(path.string());
      ADD_FAILURE() << "accepted";
    } catch (const InputError& error) {
      std::string message = error.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind(name + ":", 0), 0u) << message;
      EXPECT_NE(message.find(expected), std::string::npos) << message;
    } catch (const std::exception& error) {
      ADD_FAILURE() << "wrong exception type: " << error.what();
    }
  }
}

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
  ExpectSpectrumEq(earth.solar_irradiance, Spectrum(1.474, 1.8504, 1.91198), "irradiance");
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
  ExpectSpectrumEq(ozone.absorption_per_m, Spectrum(0.650e-6, 1.881e-6, 0.085e-6), "ozone");
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

TEST(Presets, EarthClear2008HasBrunetonNeyretParameters) {
  Atmosphere clear = LoadPreset("earth-clear-2008");
  ASSERT_EQ(clear.constituents.size(), 2u);  // no ozone
  ExpectIdentical(Find(clear, "rayleigh"), Find(LoadPreset("earth"), "rayleigh"));
  const Constituent& mie = Find(clear, "mie");
  ExpectSpectrumEq(mie.scattering_per_m, Spectrum(2e-5), "mie scattering");
  EXPECT_NEAR(mie.scattering_per_m[1] / mie.Extinction()[1], 0.9, 1e-12);
  EXPECT_EQ(mie.phase.kind, PhaseKind::kCornetteShanks);
  EXPECT_EQ(mie.phase.g, 0.76);
  EXPECT_NEAR(mie.density.At(1200.0), std::exp(-1.0), 1e-15);
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
    ExpectSpectrumEq(haze.scattering_per_m, expected.scattering, "haze scattering");
    ExpectSpectrumEq(haze.absorption_per_m, Spectrum(0.0), "haze absorption");
    EXPECT_EQ(haze.phase.kind, PhaseKind::kHenyeyGreenstein);
    EXPECT_EQ(haze.phase.g, expected.g);
    EXPECT_NEAR(haze.density.At(1250.0), std::exp(-1.0), 1e-15);  // optical length 1.25 km
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
  ExpectSpectrumEq(dust.scattering_per_m, Spectrum(53.6e-6), "dust");
  EXPECT_NEAR(dust.scattering_per_m[0] / dust.Extinction()[0], 0.99, 1e-12);
  EXPECT_EQ(dust.phase.kind, PhaseKind::kHenyeyGreenstein);
  EXPECT_EQ(dust.phase.g, 0.85);
  EXPECT_NEAR(dust.density.At(3100.0), std::exp(-1.0), 1e-15);
}

// ---------------------------------------------------------------------------
// The file format

TEST(Config, ReadmeExampleIsValid) {
  // The complete example that closes examples/atmospheres/README.md.
  std::string readme = ReadText(kPresetDir / "README.md");
  size_t section = readme.find("## A complete example");
  ASSERT_NE(section, std::string::npos);
  size_t begin = readme.find("```toml\n", section);
  ASSERT_NE(begin, std::string::npos);
  begin += 8;
  size_t end = readme.find("```", begin);
  Atmosphere example = ParseAtmosphere(readme.substr(begin, end - begin), "README.md");
  EXPECT_EQ(example.name, "example");
  EXPECT_DOUBLE_EQ(example.sun_angular_radius_rad, 0.2679 * kPi / 180.0);
}

TEST(Config, KilometresAndMetresResolveAlike) {
  std::string in_m = kMinimal;
  in_m.replace(in_m.find("ground_radius_km = 6360.0"), 25, "ground_radius_m = 6360000");
  in_m.replace(in_m.find("top_radius_km = 6420.0"), 22, "top_radius_m = 6.42e6");
  Atmosphere km = ParseMinimalWith("");
  Atmosphere m = ParseAtmosphere(in_m, "m.toml");
  EXPECT_EQ(km.bottom_radius_m, 6360000.0);
  EXPECT_EQ(km.top_radius_m, 6420000.0);
  ExpectIdentical(km, m);
}

TEST(Config, AnglesResolveToRadiansAndMuSMin) {
  std::string text = kMinimal;
  text.replace(text.find("angular_radius_rad = 0.004675"), 29, "angular_radius_deg = 0.25");
  text.replace(text.find("lowest_zenith_deg = 102.0"), 25, "lowest_zenith_deg = 180");
  Atmosphere a = ParseAtmosphere(text, "deg.toml");
  EXPECT_DOUBLE_EQ(a.sun_angular_radius_rad, 0.25 * kPi / 180.0);
  EXPECT_EQ(a.mu_s_min, -1.0);
  EXPECT_DOUBLE_EQ(ParseMinimalWith("").mu_s_min, std::cos(102.0 * kPi / 180.0));

  text.replace(text.find("lowest_zenith_deg = 180"), 23, "mu_s_min = -0.25");
  EXPECT_EQ(ParseAtmosphere(text, "mu.toml").mu_s_min, -0.25);
}

TEST(Config, DefaultsForOptionalParts) {
  Atmosphere vacuum = ParseMinimalWith("");  // zero constituents is a valid vacuum
  EXPECT_TRUE(vacuum.constituents.empty());
  EXPECT_EQ(vacuum.description, "");
  ExpectSpectrumEq(vacuum.wavelengths_nm, Spectrum(680.0, 550.0, 440.0), "default wavelengths");
  ExpectSpectrumEq(vacuum.solar_irradiance, Spectrum(1.5), "scalar irradiance");

  Atmosphere a = ParseMinimalWith(R"(
[constituents.absorber]
scattering_per_m = 0
absorption_per_m = [1, 2, 3]
density = { layers = [{ constant_term = 1 }] }
[constituents.scatterer]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { layers = [{ constant_term = 1 }] }
)");
  const Constituent& absorber = Find(a, "absorber");  // no phase: it never scatters
  EXPECT_EQ(absorber.phase.kind, PhaseKind::kIsotropic);
  ExpectSpectrumEq(absorber.absorption_per_m, Spectrum(1.0, 2.0, 3.0), "integers");
  ExpectSpectrumEq(Find(a, "scatterer").absorption_per_m, Spectrum(0.0), "default absorption");
}

TEST(Config, CoefficientForms) {
  Atmosphere a = ParseMinimalWith(R"(
[spectrum]
wavelengths_nm = [650.0, 570.0, 475.0]
[constituents.air]
phase = { function = "rayleigh" }
scattering_per_m = { refractive_index = 1.0003, number_density_per_m3 = 2.545e25, depolarization = 0.035 }
density = { layers = [{ exp_term = 1.0, exp_scale_per_m = -1.25e-4 }] }
[constituents.law]
phase = { function = "rayleigh" }
scattering_per_m = { rayleigh_at_1um = 2.0e-6 }
density = { layers = [{ constant_term = 1.0 }] }
[constituents.aerosol]
phase = { function = "henyey-greenstein", g = -0.3 }
scattering_per_m = { angstrom_reference = 1e-5, reference_nm = 570.0, exponent = 1.3 }
absorption_per_m = [1e-7, 2e-7, 3e-7]
density = { layers = [{ constant_term = 1.0 }] }
)");
  const double published[] = {6.95e-6, 1.18e-5, 2.44e-5};  // Hoffman & Preetham
  const double wavelengths_nm[] = {650.0, 570.0, 475.0};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(Find(a, "air").scattering_per_m[i] / published[i], 1.0, 0.005);
    double lambda_um = wavelengths_nm[i] / 1000.0;
    EXPECT_NEAR(Find(a, "law").scattering_per_m[i], 2.0e-6 / std::pow(lambda_um, 4), 1e-18);
    EXPECT_NEAR(Find(a, "aerosol").scattering_per_m[i],
                1e-5 * std::pow(wavelengths_nm[i] / 570.0, -1.3), 1e-18);
  }
  EXPECT_EQ(Find(a, "aerosol").scattering_per_m[1], 1e-5);  // at the reference wavelength
  ExpectSpectrumEq(Find(a, "aerosol").absorption_per_m, Spectrum(1e-7, 2e-7, 3e-7), "array");
  EXPECT_EQ(Find(a, "aerosol").phase.g, -0.3);
}

TEST(Config, TabulatedProfileInterpolatesLinearly) {
  Atmosphere a = ParseMinimalWith(R"(
[constituents.layer]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { tabulated = { altitude_m = [0.0, 1000.0, 3000.0], density = [1.0, 0.5, 0] } }
)");
  const DensityProfile& profile = Find(a, "layer").density;
  EXPECT_EQ(profile.kind, DensityProfile::Kind::kTabulated);
  EXPECT_DOUBLE_EQ(profile.At(500.0), 0.75);
  EXPECT_DOUBLE_EQ(profile.At(1000.0), 0.5);
  EXPECT_DOUBLE_EQ(profile.At(2000.0), 0.25);
  EXPECT_DOUBLE_EQ(profile.At(2500.0), 0.125);
  EXPECT_DOUBLE_EQ(profile.At(-100.0), 1.0);  // constant below the first sample
  EXPECT_DOUBLE_EQ(profile.At(9000.0), 0.0);  // and above the last
}

TEST(Config, EmptyAndClampedLayersAreAllowed) {
  Atmosphere a = ParseMinimalWith(R"(
[constituents.empty]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { layers = [{ constant_term = -1.0 }] }
[constituents.ramp]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { layers = [{ width_m = 15000.0, linear_term_per_m = 1e-4, constant_term = -0.5 }, { constant_term = 0.0 }] }
)");
  for (double h : {0.0, 1000.0, 30000.0, 60000.0}) EXPECT_EQ(Find(a, "empty").density.At(h), 0.0);
  const DensityProfile& ramp = Find(a, "ramp").density;  // negative part clamps to 0
  EXPECT_EQ(ramp.At(0.0), 0.0);
  EXPECT_DOUBLE_EQ(ramp.At(10000.0), 0.5);
}

TEST(Config, LayerMayNotExceedOneWhereItApplies) {
  // exp(h / 8 km) passes 1 above the ground: its clamp would change the
  // profile silently, so it is an error...
  std::string message = InputErrorOf([] {
    ParseMinimalWith(R"(
[constituents.inverted]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { layers = [{ exp_term = 1.0, exp_scale_per_m = 1.25e-4 }] }
)");
  });
  EXPECT_NE(message.find("constituents.inverted.density.layers[0]: density reaches"),
            std::string::npos)
      << message;
  // ...but only where the layer applies: this ramp would pass 1 above 20 km,
  // where the next layer takes over.
  Atmosphere a = ParseMinimalWith(R"(
[constituents.lower]
phase = { function = "isotropic" }
scattering_per_m = 1e-5
density = { layers = [{ width_m = 20000.0, linear_term_per_m = 5e-5 }, { constant_term = 0.5 }] }
)");
  EXPECT_DOUBLE_EQ(Find(a, "lower").density.At(19000.0), 0.95);
}

TEST(Config, ConstituentsKeepTheirFileOrder) {
  Atmosphere a = ParseMinimalWith(R"(
[constituents.zeta]
scattering_per_m = 0.0
density = { layers = [{ constant_term = 1.0 }] }
[constituents.alpha]
scattering_per_m = 0.0
density = { layers = [{ constant_term = 1.0 }] }
[constituents.mu]
scattering_per_m = 0.0
density = { layers = [{ constant_term = 1.0 }] }
)");
  ASSERT_EQ(a.constituents.size(), 3u);
  EXPECT_EQ(a.constituents[0].name, "zeta");
  EXPECT_EQ(a.constituents[1].name, "alpha");
  EXPECT_EQ(a.constituents[2].name, "mu");
  ExpectIdentical(ParseAtmosphere(ToToml(a), "again.toml"), a);
}

Atmosphere HandBuilt() {
  Atmosphere a;
  a.name = "hand \"built\"";
  a.description = "line one\nline two, with a tab\tand a backslash \\";
  a.bottom_radius_m = 1.0 / 3.0 * 1e6;
  a.top_radius_m = a.bottom_radius_m + 0.1 + 0.2;
  a.ground_albedo = Spectrum(0.0, 1.0, 1e-300);
  a.wavelengths_nm = Spectrum(700.0, 546.1, 435.8);
  a.solar_irradiance = Spectrum(0.0, 2.0 / 3.0, 1e22);
  a.sun_angular_radius_rad = 0.01;
  a.mu_s_min = -1.0;
  Constituent dust;
  dust.name = "dust storm";
  dust.scattering_per_m = Spectrum(1e-4, 2e-4, std::nextafter(3e-4, 1.0));
  dust.absorption_per_m = Spectrum(5e-7);
  dust.phase = {PhaseKind::kHenyeyGreenstein, -0.999};
  dust.density.kind = DensityProfile::Kind::kTabulated;
  dust.density.altitudes_m = {-10.0, 0.0, 123.456, 1e5};
  dust.density.densities = {2.0, 1.0, 0.1 + 0.2, 0.0};
  a.constituents.push_back(dust);
  Constituent layered;
  layered.name = "layered";
  layered.scattering_per_m = Spectrum(1e-6);
  layered.phase = {PhaseKind::kCornetteShanks, 0.5};
  layered.density.layers = {{1000.0, 0.5, -1e-3, 1e-5, 0.25}, {0.0, 0.0, 0.0, 0.0, 0.125}};
  a.constituents.push_back(layered);
  return a;
}

TEST(Config, ToTomlRoundTripsAwkwardValues) {
  Atmosphere a = HandBuilt();
  Validate(a, "hand");
  ExpectIdentical(ParseAtmosphere(ToToml(a), "hand.toml"), a);
}

TEST(Config, ToJsonHasTheSameModel) {
  Atmosphere earth = LoadPreset("earth");
  nlohmann::json json = nlohmann::json::parse(ToJson(earth));
  EXPECT_EQ(json["name"], "earth");
  EXPECT_EQ(json["planet"]["ground_radius_m"].get<double>(), earth.bottom_radius_m);
  EXPECT_EQ(json["sun"]["mu_s_min"].get<double>(), earth.mu_s_min);
  EXPECT_EQ(json["constituents"].size(), 3u);
  EXPECT_EQ(json["constituents"]["mie"]["phase"]["function"], "cornette-shanks");
  EXPECT_EQ(json["constituents"]["mie"]["phase"]["g"].get<double>(), 0.8);
  EXPECT_EQ(json["constituents"]["ozone"]["density"]["layers"].size(), 2u);
  EXPECT_EQ(json["constituents"]["rayleigh"]["scattering_per_m"][2].get<double>(),
            Find(earth, "rayleigh").scattering_per_m[2]);
}

// ---------------------------------------------------------------------------
// Validate() on hand-built models

TEST(Validate, RejectsBrokenHandBuiltAtmospheres) {
  struct Breakage {
    std::function<void(Atmosphere&)> apply;
    std::string expected;
  };
  const Breakage cases[] = {
      {[](Atmosphere& a) { a.name.clear(); }, "hand: name: must not be empty"},
      {[](Atmosphere& a) { a.top_radius_m = a.bottom_radius_m; }, "hand: planet.top_radius_m = "},
      {[](Atmosphere& a) { a.bottom_radius_m = -1.0; },
       "hand: planet.ground_radius_m = -1 must be > 0"},
      {[](Atmosphere& a) { a.ground_albedo[2] = std::nan(""); },
       "hand: planet.ground_albedo[2] = nan is not a finite number"},
      {[](Atmosphere& a) { a.wavelengths_nm[0] = 0.0; },
       "hand: spectrum.wavelengths_nm[0] = 0 must be > 0"},
      {[](Atmosphere& a) { a.solar_irradiance[1] = -1.0; },
       "hand: sun.irradiance_w_m2_nm[1] = -1 must be >= 0"},
      {[](Atmosphere& a) { a.sun_angular_radius_rad = 0.0; },
       "hand: sun.angular_radius_rad = 0 is outside (0, pi/2)"},
      {[](Atmosphere& a) { a.mu_s_min = 1.0; }, "hand: sun.mu_s_min = 1 is outside [-1, 1)"},
      {[](Atmosphere& a) { a.constituents[1].phase.g = 1.0; },
       "hand: constituents.layered.phase.g = 1 is outside (-1, 1)"},
      {[](Atmosphere& a) { a.constituents[1].phase = {PhaseKind::kRayleigh, 0.3}; },
       "hand: constituents.layered.phase.g = 0.3 is not used by the rayleigh phase function"},
      {[](Atmosphere& a) { a.constituents[0].absorption_per_m[0] = -1e-6; },
       "hand: constituents.\"dust storm\".absorption_per_m[0] = -1e-06 must be >= 0"},
      {[](Atmosphere& a) { a.constituents[1].scattering_per_m[1] = INFINITY; },
       "hand: constituents.layered.scattering_per_m[1] = inf is not a finite number"},
      {[](Atmosphere& a) { a.constituents[1].name = "dust storm"; },
       "hand: constituents.\"dust storm\": appears more than once"},
      {[](Atmosphere& a) { a.constituents[1].name.clear(); },
       "hand: constituents: a constituent has an empty name"},
      {[](Atmosphere& a) { a.constituents[1].density.layers.clear(); },
       "hand: constituents.layered.density.layers: needs at least one layer"},
      {[](Atmosphere& a) { a.constituents[1].density.layers[0].constant_term = 1.5; },
       "hand: constituents.layered.density.layers[0]: density reaches 2 at altitude 0 m"},
      {[](Atmosphere& a) { a.constituents[0].density.densities.pop_back(); },
       "hand: constituents.\"dust storm\".density.tabulated: altitude_m has 4 values but density has 3"},
      {[](Atmosphere& a) { a.constituents[0].density.altitudes_m[2] = -20.0; },
       "hand: constituents.\"dust storm\".density.tabulated.altitude_m[2] = -20 must exceed"},
  };
  for (const Breakage& breakage : cases) {
    SCOPED_TRACE(breakage.expected);
    Atmosphere a = HandBuilt();
    breakage.apply(a);
    std::string message = InputErrorOf([&] { Validate(a, "hand"); });
    EXPECT_EQ(message.rfind(breakage.expected, 0), 0u) << message;
  }
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

  // Errors name the file by its base name, not by the path it was given as.
  fs::path path = WriteScratchFile("deep/er/custom.toml", "bogus = 1\n" + kMinimal);
  std::string message = InputErrorOf([&] { LoadAtmosphere(path.string()); });
  EXPECT_EQ(message.rfind("custom.toml: bogus: unknown key", 0), 0u) << message;
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
