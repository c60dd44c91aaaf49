// Colorimetry for spectral radiance: the CIE 1931 2-degree standard observer
// and illuminant D65 (published tables in data/, compiled in), integration of
// a sampled spectrum against the colour-matching functions, chromaticity,
// and linear sRGB (IEC 61966-2-1: Rec. 709 primaries, D65 white) derived from
// its published primaries and white point.
#pragma once

#include <vector>

#include <glm/glm.hpp>

namespace skybake {

// A table on a uniform wavelength grid.
struct SpectralTable {
  double first_nm = 0.0, step_nm = 0.0;
  std::vector<glm::dvec3> values;  // one per wavelength (x_bar, y_bar, z_bar; or the value in x)
  double WavelengthNm(std::size_t i) const { return first_nm + step_nm * double(i); }
};

// data/cie1931_2deg_observer_5nm.csv: x_bar, y_bar, z_bar, 360-830 nm.
const SpectralTable& Cie1931Observer();
// data/cie_d65_5nm.csv: relative power (in x), 300-830 nm, 1 at 560 nm.
const SpectralTable& CieD65();

// The tristimulus values X, Y, Z = integral of S(lambda) times x_bar, y_bar,
// z_bar d lambda (lambda in nm) of the spectrum S that is linear between the
// given samples (wavelengths increasing) and 0 outside them, integrated by
// the trapezoid rule on the observer's 5 nm grid. Linear in the values, so
// the bake can turn N wavelengths into XYZ with N weights (XyzWeights).
glm::dvec3 SpectrumToXyz(const std::vector<double>& wavelength_nm, const std::vector<double>& value);
// The weights w_i with SpectrumToXyz(wavelength_nm, v) = sum_i w_i v_i.
std::vector<glm::dvec3> XyzWeights(const std::vector<double>& wavelength_nm);

// CIE 1931 chromaticity (x, y) = (X, Y) / (X + Y + Z).
glm::dvec2 Chromaticity(const glm::dvec3& xyz);
// CIE 1976 UCS chromaticity (u', v') = (4X, 9Y) / (X + 15Y + 3Z), where
// distances are closer to perceived colour differences than in (x, y).
glm::dvec2 UcsChromaticity(const glm::dvec3& xyz);

// The matrix from linear RGB to XYZ of an RGB space given by the
// chromaticities of its primaries and of its white (scaled so that RGB
// (1, 1, 1) has Y = 1): the columns are the primaries' XYZ, each scaled so
// that they sum to the white's XYZ (SMPTE RP 177).
glm::dmat3 RgbToXyzMatrix(const glm::dvec2& red, const glm::dvec2& green, const glm::dvec2& blue,
                          const glm::dvec2& white);
// Linear sRGB (IEC 61966-2-1: primaries (0.64, 0.33), (0.30, 0.60),
// (0.15, 0.06), white D65 (0.3127, 0.3290)) to XYZ and back.
const glm::dmat3& LinearSrgbToXyzMatrix();
const glm::dmat3& XyzToLinearSrgbMatrix();

}  // namespace skybake
