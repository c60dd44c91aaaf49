#include "reference/spectral_reference.h"

#include <cmath>

namespace skybake::reference {

namespace {

glm::dmat3 Abs(const glm::dmat3& m) {
  glm::dmat3 a;
  for (int c = 0; c < 3; ++c) a[c] = glm::abs(m[c]);
  return a;
}

// Sunlight's colour through a transmittance: XYZ of E T over XYZ of E,
// summed over the batches (0 where the sun has no colour).
struct SunColour {
  Spectrum through{0.0}, unattenuated{0.0};
  Spectrum Transmittance() const {
    Spectrum t(0.0);
    for (int c = 0; c < kWavelengthCount; ++c) t[c] = unattenuated[c] > 0.0 ? through[c] / unattenuated[c] : 0.0;
    return t;
  }
};

}  // namespace

std::vector<Result> EvaluateSpectral(const AtmosphereSource& source, const SpectralBatches& batches,
                                     const std::vector<Query>& queries, const Settings& settings,
                                     const QueryProgress& progress) {
  std::vector<Result> xyz(queries.size());
  std::vector<SunColour> transmittance(queries.size()), transmittance_error(queries.size());
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const Atmosphere atmosphere = ParseAtmosphere(source.text, source.name, batches.batch_wavelengths_nm[b]);
    const PathTracer tracer(atmosphere);
    const glm::dmat3& m = batches.to_xyz[b];
    const glm::dmat3 m_abs = Abs(m);
    const Spectrum sun_xyz = m * atmosphere.solar_irradiance;
    for (std::size_t row = 0; row < queries.size(); ++row) {
      const Result r = tracer.Evaluate(queries[row], settings, row);
      Result& out = xyz[row];
      out.radiance.mean += m * r.radiance.mean;
      out.radiance.standard_error += m_abs * r.radiance.standard_error;
      transmittance[row].through += m * (atmosphere.solar_irradiance * r.transmittance);
      transmittance[row].unattenuated += sun_xyz;
      transmittance_error[row].through += m_abs * (atmosphere.solar_irradiance * r.transmittance_error);
      transmittance_error[row].unattenuated += sun_xyz;
      out.has_irradiance = r.has_irradiance;
      out.sun_irradiance += m * r.sun_irradiance;
      out.sun_irradiance_error += m_abs * r.sun_irradiance_error;
      out.sky_irradiance.mean += m * r.sky_irradiance.mean;
      out.sky_irradiance.standard_error += m_abs * r.sky_irradiance.standard_error;
      out.statistics.paths += r.statistics.paths;
      out.statistics.vertices += r.statistics.vertices;
      out.statistics.truncated += r.statistics.truncated;
      out.statistics.seconds += r.statistics.seconds;
      if (progress) progress();
    }
  }
  for (std::size_t row = 0; row < queries.size(); ++row) {
    xyz[row].transmittance = transmittance[row].Transmittance();
    xyz[row].transmittance_error = transmittance_error[row].Transmittance();
  }
  return xyz;
}

}  // namespace skybake::reference
