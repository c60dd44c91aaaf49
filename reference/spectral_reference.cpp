#include "reference/spectral_reference.h"

#include <cmath>

namespace skybake::reference {

namespace {

glm::dmat3 Abs(const glm::dmat3& m) {
  glm::dmat3 a;
  for (int c = 0; c < 3; ++c) a[c] = glm::abs(m[c]);
  return a;
}

// Sunlight's colour through a transmittance: the XYZ of E T, summed over
// the batches, over the sun's XYZ (0 in a channel where the sun has none).
Spectrum SunColourTransmittance(const Spectrum& through, const Spectrum& sun_xyz) {
  Spectrum t(0.0);
  for (int c = 0; c < kWavelengthCount; ++c) t[c] = sun_xyz[c] > 0.0 ? through[c] / sun_xyz[c] : 0.0;
  return t;
}

}  // namespace

std::vector<Result> EvaluateSpectral(const AtmosphereSource& source, const SpectralBatches& batches,
                                     const std::vector<Query>& queries, const Settings& settings,
                                     const QueryProgress& progress) {
  std::vector<Result> xyz(queries.size());
  std::vector<Spectrum> sun_through(queries.size(), Spectrum(0.0)), sun_error(queries.size(), Spectrum(0.0));
  Spectrum sun_xyz(0.0);
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const Atmosphere atmosphere = ParseAtmosphere(source.text, source.name, batches.batch_wavelengths_nm[b]);
    const PathTracer tracer(atmosphere);
    const glm::dmat3& m = batches.to_xyz[b];
    const glm::dmat3 m_abs = Abs(m);
    sun_xyz += m * atmosphere.solar_irradiance;
    for (std::size_t row = 0; row < queries.size(); ++row) {
      const Result r = tracer.Evaluate(queries[row], settings, row);
      Result& out = xyz[row];
      out.radiance.mean += m * r.radiance.mean;
      out.radiance.standard_error += m_abs * r.radiance.standard_error;
      sun_through[row] += m * (atmosphere.solar_irradiance * r.transmittance);
      sun_error[row] += m_abs * (atmosphere.solar_irradiance * r.transmittance_error);
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
    xyz[row].transmittance = SunColourTransmittance(sun_through[row], sun_xyz);
    xyz[row].transmittance_error = SunColourTransmittance(sun_error[row], sun_xyz);
  }
  return xyz;
}

}  // namespace skybake::reference
