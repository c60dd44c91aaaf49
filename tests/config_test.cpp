// Atmosphere files: malformed files, the file format, and Validate() on
// hand-built models. Presets, LoadAtmosphere and the `presets` / `validate`
// commands are tested in config_presets_test.cpp.
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
      EXPECT_EQ(message.rfind(path.string() + ":", 0), 0u) << message;
      EXPECT_NE(message.find(expected), std::string::npos) << message;
    } catch (const std::exception& error) {
      ADD_FAILURE() << "wrong exception type: " << error.what();
    }
  }
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

// A published spectrum as (wavelength, value) pairs: linear between them,
// exact at a tabulated wavelength.
TEST(Config, TabulatedCoefficientInterpolatesLinearlyInWavelength) {
  Atmosphere a = ParseMinimalWith(R"(
[spectrum]
wavelengths_nm = [680.0, 600.0, 440.0]
[constituents.ozone]
scattering_per_m = 0.0
absorption_per_m = { wavelength_nm = [400.0, 500.0, 600.0, 700.0], per_m = [0.0, 1.0e-6, 2.0e-6, 0.5e-6] }
density = { layers = [{ constant_term = 1.0 }] }
)");
  const Spectrum& absorption = Find(a, "ozone").absorption_per_m;
  EXPECT_DOUBLE_EQ(absorption[0], 2.0e-6 + (0.5e-6 - 2.0e-6) * 0.8);  // 680 nm, 4/5 of the way to 700
  EXPECT_EQ(absorption[1], 2.0e-6);                                    // 600 nm, a tabulated wavelength
  EXPECT_DOUBLE_EQ(absorption[2], 0.4e-6);                             // 440 nm
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
       "hand: sun.angular_radius_rad = 0 is outside [1e-6, pi/2)"},
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

}  // namespace
}  // namespace skybake
