// Helpers shared by the tests of atmosphere files and presets
// (config_test.cpp, config_presets_test.cpp): the preset files, scratch
// files, bit-exact comparison of atmospheres and a minimal valid file.
#pragma once

#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "bake/config.h"
#include "core/errors.h"
#include "test_util.h"

namespace skybake {

inline const std::filesystem::path kSourceDir = SKYBAKE_SOURCE_DIR;
inline const std::filesystem::path kPresetDir = kSourceDir / "examples" / "atmospheres";
inline const std::set<std::string> kPresetNames = {"earth",      "earth-clear-2008", "light-haze",
                                            "heavy-haze", "light-fog",        "heavy-fog",
                                            "mars"};

using testing::ReadText;

inline const std::filesystem::path& ScratchDir() {
  static const testing::TempDir scratch;
  return scratch.path();
}

inline std::filesystem::path WriteScratchFile(const std::string& name, const std::string& text) {
  std::filesystem::path path = ScratchDir() / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

inline std::string InputErrorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

inline void ExpectSpectrumEq(const Spectrum& a, const Spectrum& b, const std::string& what) {
  for (int i = 0; i < kWavelengthCount; ++i) EXPECT_EQ(a[i], b[i]) << what << "[" << i << "]";
}

inline void ExpectIdentical(const Constituent& a, const Constituent& b) {
  SCOPED_TRACE("constituent " + a.name);
  EXPECT_EQ(a.name, b.name);
  ExpectSpectrumEq(a.scattering_per_m, b.scattering_per_m, "scattering_per_m");
  ExpectSpectrumEq(a.absorption_per_m, b.absorption_per_m, "absorption_per_m");
  EXPECT_TRUE(a.scattering_form == b.scattering_form) << "scattering_form";
  EXPECT_TRUE(a.absorption_form == b.absorption_form) << "absorption_form";
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
inline void ExpectIdentical(const Atmosphere& a, const Atmosphere& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.bottom_radius_m, b.bottom_radius_m);
  EXPECT_EQ(a.top_radius_m, b.top_radius_m);
  ExpectSpectrumEq(a.ground_albedo, b.ground_albedo, "ground_albedo");
  ExpectSpectrumEq(a.wavelengths_nm, b.wavelengths_nm, "wavelengths_nm");
  ExpectSpectrumEq(a.solar_irradiance, b.solar_irradiance, "solar_irradiance");
  EXPECT_TRUE(a.ground_albedo_form == b.ground_albedo_form) << "ground_albedo_form";
  EXPECT_TRUE(a.solar_irradiance_form == b.solar_irradiance_form) << "solar_irradiance_form";
  EXPECT_EQ(a.sun_angular_radius_rad, b.sun_angular_radius_rad);
  EXPECT_EQ(a.mu_s_min, b.mu_s_min);
  ASSERT_EQ(a.constituents.size(), b.constituents.size());
  for (size_t i = 0; i < a.constituents.size(); ++i)
    ExpectIdentical(a.constituents[i], b.constituents[i]);
}

inline const Constituent& Find(const Atmosphere& atmosphere, const std::string& name) {
  for (const Constituent& c : atmosphere.constituents) {
    if (c.name == name) return c;
  }
  throw std::runtime_error(atmosphere.name + " has no constituent " + name);
}

// A valid file without constituents; tests append to it.
inline const std::string kMinimal = R"(
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

inline Atmosphere ParseMinimalWith(const std::string& extra) {
  return ParseAtmosphere(kMinimal + extra, "test.toml");
}

}  // namespace skybake
