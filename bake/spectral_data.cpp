#include "bake/spectral_data.h"

#include <algorithm>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "shaders_runtime/embedded_text.h"

namespace skybake {

SpectralData ReadSpectralData(std::string_view name, int columns) {
  const auto file = std::find_if(kSpectralDataFiles.begin(), kSpectralDataFiles.end(),
                                 [&](const EmbeddedText& f) { return f.name == name; });
  if (file == kSpectralDataFiles.end()) throw InternalError("no embedded data file " + std::string(name));
  SpectralData data;
  std::istringstream in{std::string(file->text)};
  bool header = true;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    double wavelength = 0.0;
    glm::dvec3 value(0.0);
    row >> wavelength;
    for (int c = 0; c < columns; ++c) row >> value[c];
    if (!row) throw InternalError(std::string(name) + ": malformed row '" + line + "'");
    if (!data.wavelength_nm.empty() && !(wavelength > data.wavelength_nm.back())) {
      throw InternalError(std::string(name) + ": wavelengths not increasing at " + std::to_string(wavelength));
    }
    data.wavelength_nm.push_back(wavelength);
    data.values.push_back(value);
  }
  if (data.wavelength_nm.size() < 2) throw InternalError(std::string(name) + ": fewer than two rows");
  return data;
}

const SpectralData& AstmG173() {
  static const SpectralData data = ReadSpectralData("astm_g173_03.csv", 3);
  return data;
}

const SpectralData& OzoneCrossSection233K() {
  static const SpectralData data = ReadSpectralData("ozone_cross_section_233k_10nm.csv", 1);
  return data;
}

double AstmG173ExtraterrestrialBinMean(double from_nm, double width_nm) {
  const SpectralData& data = AstmG173();
  double sum = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < data.wavelength_nm.size(); ++i) {
    if (data.wavelength_nm[i] >= from_nm && data.wavelength_nm[i] < from_nm + width_nm) {
      sum += data.values[i].x;
      ++count;
    }
  }
  if (count == 0) {
    throw InputError("no ASTM G173-03 sample between " + std::to_string(from_nm) + " and " +
                     std::to_string(from_nm + width_nm) + " nm (the table covers 280 to 4000 nm)");
  }
  return sum / count;
}

}  // namespace skybake
