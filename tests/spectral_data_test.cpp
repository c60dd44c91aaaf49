// The solar spectrum shipped in data/ (ASTM G173-03) against published
// values, and `sun.irradiance_w_m2_nm = "astm-g173"` in atmosphere files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "bake/config.h"
#include "bake/spectral_data.h"
#include "core/errors.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

// Trapezoid integral of one column over the table's own wavelengths.
double Integral(const SpectralData& data, int column) {
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < data.wavelength_nm.size(); ++i) {
    sum += 0.5 * (data.values[i][column] + data.values[i + 1][column]) *
           (data.wavelength_nm[i + 1] - data.wavelength_nm[i]);
  }
  return sum;
}

// ASTM G173-03 states the integrated irradiance of its two terrestrial
// spectra, 280-4000 nm: 1000.4 W m^-2 (global tilt, "AM1.5G") and
// 900.1 W m^-2 (direct + circumsolar, "AM1.5D"). The whole transcription
// (2002 rows of three columns) has to be right for both to come out, to the
// published figures' 0.05 W m^-2 rounding.
TEST(AstmG173, TerrestrialSpectraIntegrateToThePublishedIrradiances) {
  const SpectralData& data = AstmG173();
  ASSERT_EQ(data.wavelength_nm.size(), 2002u);
  EXPECT_EQ(data.wavelength_nm.front(), 280.0);
  EXPECT_EQ(data.wavelength_nm.back(), 4000.0);
  EXPECT_NEAR(Integral(data, 1), 1000.4, 0.05);
  EXPECT_NEAR(Integral(data, 2), 900.1, 0.05);
  std::printf("ASTM G173-03, 280-4000 nm: extraterrestrial %.2f, global tilt %.2f, direct %.2f W/m^2\n",
              Integral(data, 0), Integral(data, 1), Integral(data, 2));
}

// The 10 nm bin means of the extraterrestrial spectrum are the solar
// irradiance of Bruneton's 2017 implementation (its kSolarIrradiance table,
// bins named by their lower edge), which the earth preset's three values
// copy: 1.11776 and 1.14259 at 360 and 370 nm there, and 1.474, 1.8504 and
// 1.91198 at 680, 550 and 440 nm; published to five or six digits.
TEST(AstmG173, TenNanometreBinMeansAreTheSolarIrradianceOfThePresets) {
  const std::pair<double, double> published[] = {{360.0, 1.11776}, {370.0, 1.14259}, {440.0, 1.91198},
                                                 {550.0, 1.8504},  {680.0, 1.474}};
  for (const auto& [nm, value] : published) {
    EXPECT_NEAR(AstmG173ExtraterrestrialBinMean(nm), value, 5e-6) << nm << " nm";
  }
  // Every preset's sun: the bin means at its wavelengths; on Mars, at 1.524 AU,
  // divided by 1.524^2 (mars.toml).
  for (const char* preset : {"earth", "earth-clear-2008", "light-haze", "heavy-haze", "light-fog", "heavy-fog", "mars"}) {
    const Atmosphere atmosphere = LoadAtmosphere(preset);
    const double scale = std::string(preset) == "mars" ? 1.0 / (1.524 * 1.524) : 1.0;
    for (int i = 0; i < kWavelengthCount; ++i) {
      const double expected = AstmG173ExtraterrestrialBinMean(atmosphere.wavelengths_nm[i]) * scale;
      EXPECT_NEAR(atmosphere.solar_irradiance[i], expected, 5e-6 * expected) << preset << " channel " << i;
    }
  }
  EXPECT_THROW(AstmG173ExtraterrestrialBinMean(4001.0), InputError);
}

std::string AtmosphereWithSun(const std::string& irradiance, const std::string& wavelengths = "[680.0, 550.0, 440.0]") {
  return "name = \"t\"\n[planet]\nground_radius_km = 6360.0\ntop_radius_km = 6420.0\nground_albedo = 0.1\n"
         "[spectrum]\nwavelengths_nm = " + wavelengths + "\n"
         "[sun]\nirradiance_w_m2_nm = " + irradiance + "\nangular_radius_rad = 0.004675\nlowest_zenith_deg = 102.0\n"
         "[constituents.rayleigh]\nphase = { function = \"rayleigh\" }\n"
         "scattering_per_m = { rayleigh_at_1um = 1.24062e-6 }\n"
         "density = { layers = [{ exp_term = 1.0, exp_scale_per_m = -1.25e-4 }] }\n";
}

TEST(AstmG173, AtmosphereFilesNameItForTheSun) {
  const Atmosphere named = ParseAtmosphere(AtmosphereWithSun("\"astm-g173\""), "named.toml");
  const Atmosphere earth = LoadAtmosphere("earth");
  for (int i = 0; i < kWavelengthCount; ++i) {
    EXPECT_EQ(named.solar_irradiance[i], AstmG173ExtraterrestrialBinMean(named.wavelengths_nm[i]));
    EXPECT_NEAR(named.solar_irradiance[i], earth.solar_irradiance[i], 5e-6);
  }
  // Other wavelengths take their own bins.
  const Atmosphere blue = ParseAtmosphere(AtmosphereWithSun("\"astm-g173\"", "[650.0, 500.0, 400.0]"), "b.toml");
  EXPECT_EQ(blue.solar_irradiance[2], AstmG173ExtraterrestrialBinMean(400.0));
  EXPECT_NE(blue.solar_irradiance[2], named.solar_irradiance[2]);

  // Bad input: one line, naming the key.
  struct Case {
    std::string irradiance, wavelengths, message;
  };
  for (const Case& c : {Case{"\"kurucz\"", "[680.0, 550.0, 440.0]", "unknown spectrum \"kurucz\""},
                        Case{"\"astm-g173\"", "[3995.0, 550.0, 440.0]", "covers 280 to 4000 nm"},
                        Case{"true", "[680.0, 550.0, 440.0]", "expected a number, an array of 3 numbers or"}}) {
    SCOPED_TRACE(c.irradiance);
    try {
      ParseAtmosphere(AtmosphereWithSun(c.irradiance, c.wavelengths), "bad.toml");
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("sun.irradiance_w_m2_nm"), std::string::npos) << what;
      EXPECT_NE(what.find(c.message), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// Ozone's Chappuis band: the absorption cross-section peaks near 602 nm at
// about 5e-21 cm^2 (5e-25 m^2), weakly dependent on temperature
// (Gorshelev et al. 2014; Burrows et al. 1999 list 5.2e-21 cm^2 at 293 K),
// and falls by three orders of magnitude to the minimum between the Huggins
// and Chappuis bands near 370-380 nm. The 10 nm bin holding 602 nm must be
// the table's largest and within 10% of 5e-25 m^2 (the spread of the
// published maxima), and the smallest bin lies between 360 and 390 nm.
TEST(OzoneCrossSection, ChappuisBandPeaksNear602NanometresAtItsPublishedSize) {
  const SpectralData& sigma = OzoneCrossSection233K();
  ASSERT_EQ(sigma.wavelength_nm.size(), 48u);
  EXPECT_EQ(sigma.wavelength_nm.front(), 360.0);
  EXPECT_EQ(sigma.wavelength_nm.back(), 830.0);
  std::size_t peak = 0, trough = 0;
  for (std::size_t i = 0; i < sigma.values.size(); ++i) {
    if (sigma.values[i].x > sigma.values[peak].x) peak = i;
    if (sigma.values[i].x < sigma.values[trough].x) trough = i;
  }
  EXPECT_EQ(sigma.wavelength_nm[peak], 600.0);  // the bin [600, 610) nm
  EXPECT_NEAR(sigma.values[peak].x, 5e-25, 0.5e-25);
  EXPECT_GE(sigma.wavelength_nm[trough], 360.0);
  EXPECT_LE(sigma.wavelength_nm[trough], 390.0);
  EXPECT_LT(sigma.values[trough].x, 1e-3 * sigma.values[peak].x);
}

// The earth preset's ozone: the cross-section times 300 Dobson units
// (2.687e20 molecules m^-2 each) spread over its tent profile, whose integral
// is 15 km; at 680/550/440 nm the 3-digit values of Bruneton's 2017
// parameters, which were rounded from the same products.
TEST(OzoneCrossSection, EarthPresetHoldsThreeHundredDobsonUnits) {
  const Atmosphere earth = LoadAtmosphere("earth");
  const Constituent* ozone = nullptr;
  for (const Constituent& c : earth.constituents) {
    if (c.name == "ozone") ozone = &c;
  }
  ASSERT_NE(ozone, nullptr);
  double column = 0.0;  // integral of the density over altitude, m
  for (double h = 5.0; h < 60000.0; h += 10.0) column += ozone->density.At(h) * 10.0;
  EXPECT_NEAR(column, 15000.0, 1.0);
  const SpectralData& sigma = OzoneCrossSection233K();
  const std::size_t at_550 = 19;
  ASSERT_EQ(sigma.wavelength_nm[at_550], 550.0);
  const double molecules = ozone->absorption_per_m[1] / sigma.values[at_550].x;
  EXPECT_NEAR(molecules * column / 2.687e20, 300.0, 0.01);
  const Spectrum bruneton(0.650e-6, 1.881e-6, 0.085e-6);
  for (int i = 0; i < kWavelengthCount; ++i) {
    EXPECT_NEAR(ozone->absorption_per_m[i], bruneton[i], 0.0005 * bruneton[i]) << earth.wavelengths_nm[i] << " nm";
  }
}

}  // namespace
}  // namespace skybake
