#include "bake/colour.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>

#include "bake/spectral_data.h"
#include "core/interpolation.h"
#include "core/errors.h"

namespace skybake {

namespace {

// One of data/*.csv on a uniform wavelength grid.
SpectralTable ReadTable(std::string_view name, int columns) {
  const SpectralData data = ReadSpectralData(name, columns);
  SpectralTable table;
  table.first_nm = data.wavelength_nm.front();
  table.step_nm = data.wavelength_nm[1] - data.wavelength_nm[0];
  table.values = data.values;
  for (std::size_t i = 0; i < data.wavelength_nm.size(); ++i) {
    if (std::abs(data.wavelength_nm[i] - table.WavelengthNm(i)) > 1e-9) {
      throw InternalError(std::string(name) + ": wavelengths not on a uniform grid");
    }
  }
  return table;
}

// The value at `nm` of the spectrum linear between the samples, 0 outside.
double Interpolate(const std::vector<double>& wavelength_nm, const std::vector<double>& value, double nm) {
  if (nm < wavelength_nm.front() || nm > wavelength_nm.back()) return 0.0;
  return PiecewiseLinear(wavelength_nm, value, nm);
}

}  // namespace

const SpectralTable& Cie1931Observer() {
  static const SpectralTable table = ReadTable("cie1931_2deg_observer_5nm.csv", 3);
  return table;
}

const SpectralTable& CieD65() {
  static const SpectralTable table = ReadTable("cie_d65_5nm.csv", 1);
  return table;
}

glm::dvec3 SpectrumToXyz(const std::vector<double>& wavelength_nm, const std::vector<double>& value) {
  if (wavelength_nm.size() != value.size() || wavelength_nm.empty()) {
    throw InternalError("SpectrumToXyz: " + std::to_string(wavelength_nm.size()) + " wavelengths, " +
                        std::to_string(value.size()) + " values");
  }
  if (!std::is_sorted(wavelength_nm.begin(), wavelength_nm.end())) {
    throw InternalError("SpectrumToXyz: wavelengths not increasing");
  }
  const SpectralTable& observer = Cie1931Observer();
  glm::dvec3 xyz(0.0);
  const std::size_t n = observer.values.size();
  for (std::size_t i = 0; i < n; ++i) {
    // Trapezoid weights: half a step at both ends of the grid.
    const double weight = (i == 0 || i + 1 == n ? 0.5 : 1.0) * observer.step_nm;
    xyz += weight * Interpolate(wavelength_nm, value, observer.WavelengthNm(i)) * observer.values[i];
  }
  return xyz;
}

std::vector<glm::dvec3> XyzWeights(const std::vector<double>& wavelength_nm) {
  std::vector<glm::dvec3> weights;
  std::vector<double> unit(wavelength_nm.size(), 0.0);
  for (std::size_t i = 0; i < wavelength_nm.size(); ++i) {
    unit[i] = 1.0;
    weights.push_back(SpectrumToXyz(wavelength_nm, unit));
    unit[i] = 0.0;
  }
  return weights;
}

glm::dvec2 Chromaticity(const glm::dvec3& xyz) {
  const double sum = xyz.x + xyz.y + xyz.z;
  return sum > 0.0 ? glm::dvec2(xyz.x, xyz.y) / sum : glm::dvec2(0.0);
}

glm::dvec2 UcsChromaticity(const glm::dvec3& xyz) {
  const double denominator = xyz.x + 15.0 * xyz.y + 3.0 * xyz.z;
  return denominator > 0.0 ? glm::dvec2(4.0 * xyz.x, 9.0 * xyz.y) / denominator : glm::dvec2(0.0);
}

glm::dmat3 RgbToXyzMatrix(const glm::dvec2& red, const glm::dvec2& green, const glm::dvec2& blue,
                          const glm::dvec2& white) {
  // XYZ of chromaticity (x, y) at Y = 1: (x / y, 1, (1 - x - y) / y).
  auto xyz = [](const glm::dvec2& c) { return glm::dvec3(c.x / c.y, 1.0, (1.0 - c.x - c.y) / c.y); };
  const glm::dmat3 primaries(xyz(red), xyz(green), xyz(blue));  // columns
  const glm::dvec3 scale = glm::inverse(primaries) * xyz(white);
  return glm::dmat3(primaries[0] * scale.x, primaries[1] * scale.y, primaries[2] * scale.z);
}

const glm::dmat3& LinearSrgbToXyzMatrix() {
  static const glm::dmat3 m = RgbToXyzMatrix({0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, {0.3127, 0.3290});
  return m;
}

const glm::dmat3& XyzToLinearSrgbMatrix() {
  static const glm::dmat3 m = glm::inverse(LinearSrgbToXyzMatrix());
  return m;
}

}  // namespace skybake
