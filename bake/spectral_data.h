// The published spectra compiled in from data/ (data/README.md): reading
// them, the solar spectrum (ASTM G173-03) with the bin means an atmosphere
// file's `sun.irradiance_w_m2_nm = "astm-g173"` takes, and ozone's absorption
// cross-section (`{ cross_section = "ozone-233k", ... }`).
#pragma once

#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace skybake {

// One of data/*.csv: its wavelengths (increasing) and up to three columns
// of values per wavelength.
struct SpectralData {
  std::vector<double> wavelength_nm;
  std::vector<glm::dvec3> values;
};

// Reads data/<name>: '#' comment lines, a header, then rows of a wavelength
// and `columns` values. InternalError if it is not embedded or malformed.
SpectralData ReadSpectralData(std::string_view name, int columns);

// data/astm_g173_03.csv: extraterrestrial (x), global tilt (y) and direct
// plus circumsolar (z) spectral irradiance, W m^-2 nm^-1, 280-4000 nm.
const SpectralData& AstmG173();

// The mean of the extraterrestrial samples of ASTM G173-03 with
// from_nm <= lambda < from_nm + width_nm, W m^-2 nm^-1: the binning of the
// solar irradiance in Bruneton's 2017 implementation (10 nm bins named by
// their lower edge), which the presets' three values follow.
// InputError if the bin holds no sample.
double AstmG173ExtraterrestrialBinMean(double from_nm, double width_nm = 10.0);

// data/ozone_cross_section_233k_10nm.csv: ozone's absorption cross-section
// at 233 K (Serdyuchenko et al. 2014), m^2, 10 nm bin means named by their
// lower edge, 360-830 nm (in x).
const SpectralData& OzoneCrossSection233K();

}  // namespace skybake
