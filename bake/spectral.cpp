#include "bake/spectral.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>

#include "bake/colour.h"
#include "core/errors.h"

namespace skybake {

std::vector<double> SpectralWavelengths(int count) {
  if (count < kWavelengthCount) {
    throw InputError("a spectral bake needs at least 3 wavelengths, not " + std::to_string(count));
  }
  std::vector<double> wavelengths;
  for (int i = 0; i < count; ++i) {
    wavelengths.push_back(kSpectralFirstNm + (kSpectralLastNm - kSpectralFirstNm) * double(i) / double(count - 1));
  }
  return wavelengths;
}

SpectralBatches MakeSpectralBatches(const std::vector<double>& wavelengths_nm) {
  SpectralBatches batches;
  batches.wavelengths_nm = wavelengths_nm;
  const std::vector<glm::dvec3> weights = XyzWeights(wavelengths_nm);
  for (std::size_t first = 0; first < wavelengths_nm.size(); first += kWavelengthCount) {
    Spectrum nm(0.0);
    glm::dmat3 to_xyz(0.0);
    for (int c = 0; c < kWavelengthCount; ++c) {
      const std::size_t i = first + c;
      nm[c] = wavelengths_nm[std::min(i, wavelengths_nm.size() - 1)];
      if (i < wavelengths_nm.size()) to_xyz[c] = kLuminousEfficacyLmPerW * weights[i];
    }
    batches.batch_wavelengths_nm.push_back(nm);
    batches.to_xyz.push_back(to_xyz);
  }
  return batches;
}

namespace {

// Per texel and channel, the sum over batches of to_xyz times the batch's
// texel (radiance tables), in double until stored.
class XyzSum {
 public:
  explicit XyzSum(const glsl::Texture& shape)
      : width_(shape.width), height_(shape.height), depth_(shape.depth),
        sum_(std::size_t(shape.width) * shape.height * shape.depth, glm::dvec3(0.0)) {}

  void Add(const glm::dmat3& to_xyz, const glsl::Texture& texture) {
    for (std::size_t i = 0; i < sum_.size(); ++i) {
      const float* t = &texture.texels[4 * i];
      sum_[i] += to_xyz * glm::dvec3(t[0], t[1], t[2]);
    }
  }
  glsl::Texture Texture() const {
    glsl::Texture out(width_, height_, depth_);
    for (std::size_t i = 0; i < sum_.size(); ++i) {
      for (int c = 0; c < 3; ++c) out.texels[4 * i + c] = float(sum_[i][c]);
    }
    return out;
  }

 private:
  int width_, height_, depth_;
  std::vector<glm::dvec3> sum_;
};

// Sunlight's colour through the transmittance table's rays, per texel and
// channel: -ln(sum_i a_i exp(-tau_i) / sum_i a_i) with a_i >= 0 the sun's
// XYZ weight at wavelength i, summed with the smallest depth factored out
// so that long, opaque rays do not underflow to 0.
class SunlightDepth {
 public:
  explicit SunlightDepth(const glsl::Texture& shape)
      : width_(shape.width), height_(shape.height), terms_(std::size_t(shape.width) * shape.height) {}

  // Column w of `sun_weights`: the XYZ weight of the depth in channel w.
  void Add(const glm::dmat3& sun_weights, const glsl::Texture& depth) {
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      for (int w = 0; w < 3; ++w) terms_[i].push_back({sun_weights[w], double(depth.texels[4 * i + w])});
    }
  }
  glsl::Texture Texture() const {
    glsl::Texture out(width_, height_);
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        double smallest = std::numeric_limits<double>::infinity(), weight_sum = 0.0;
        for (const Term& t : terms_[i]) {
          if (t.weight[c] > 0.0) smallest = std::min(smallest, t.depth);
          weight_sum += t.weight[c];
        }
        double sum = 0.0;
        for (const Term& t : terms_[i]) sum += t.weight[c] * std::exp(smallest - t.depth);
        out.texels[4 * i + c] = weight_sum > 0.0 ? float(smallest - std::log(sum / weight_sum)) : 0.0f;
      }
    }
    return out;
  }

 private:
  struct Term {
    glm::dvec3 weight;  // per XYZ channel, of one wavelength
    double depth;
  };
  int width_, height_;
  std::vector<std::vector<Term>> terms_;
};

}  // namespace

LutSet BakeSpectral(const AtmosphereSource& source, const SpectralBatches& batches, const BakeSettings& settings,
                    BakeReport* report, const BakeProgress& progress) {
  if (settings.pack_single_mie_in_alpha) {
    throw InputError("--pack-mie: a spectral bake keeps single Mie in its own table (its alpha would hold one "
                     "wavelength, not a colour)");
  }
  if (settings.scattering_range) throw InputError("a spectral bake covers the whole atmosphere (no scene range)");
  // Every batch's atmosphere first, so that a file not defined at some
  // wavelength fails before anything is baked.
  std::vector<Atmosphere> atmospheres;
  for (const Spectrum& nm : batches.batch_wavelengths_nm) {
    atmospheres.push_back(ParseAtmosphere(source.text, source.name, nm));
  }
  LutSet out;
  out.atmosphere = ParseAtmosphere(source.text, source.name);
  out.colour = SpectralColour{batches.wavelengths_nm};
  std::optional<XyzSum> irradiance, scattering, single_mie;
  std::optional<SunlightDepth> transmittance;
  glm::dvec3 sun_xyz(0.0);
  using Profile = std::array<glsl::vec3, glsl::ALTITUDE_PROFILE_SIZE>;
  Profile extinction{}, mie{}, rayleigh{};
  BakeReport total;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const Spectrum& nm = batches.batch_wavelengths_nm[b];
    const Atmosphere& atmosphere = atmospheres[b];
    char name[64];
    std::snprintf(name, sizeof(name), "%.0f-%.0f nm: ", nm.x, nm.z);
    BakeReport batch_report;
    const LutSet luts = Bake(atmosphere, settings, &batch_report, [&](const BakeTiming& t) {
      if (progress) progress({name + t.phase, t.seconds});
    });
    for (const BakeTiming& t : batch_report.timings) total.timings.push_back({name + t.phase, t.seconds});
    total.total_seconds += batch_report.total_seconds;
    total.orders_used = std::max(total.orders_used, batch_report.orders_used);
    total.order_ratio = std::max(total.order_ratio, batch_report.order_ratio);
    total.extrapolated_tail = std::max(total.extrapolated_tail, batch_report.extrapolated_tail);
    total.remaining_error = std::max(total.remaining_error, batch_report.remaining_error);

    const glm::dmat3& m = batches.to_xyz[b];
    if (b == 0) {
      out.settings = luts.settings;
      out.parameters = luts.parameters;
      irradiance.emplace(luts.irradiance);
      scattering.emplace(luts.scattering);
      single_mie.emplace(luts.single_mie_scattering);
      transmittance.emplace(luts.transmittance);
    }
    out.orders_used = std::max(out.orders_used, luts.orders_used);
    irradiance->Add(m, luts.irradiance);
    scattering->Add(m, luts.scattering);
    single_mie->Add(m, luts.single_mie_scattering);
    // The sun's XYZ weight of each of the batch's wavelengths: column w of m
    // times the irradiance there.
    const Spectrum& e = atmosphere.solar_irradiance;
    transmittance->Add(glm::dmat3(m[0] * e[0], m[1] * e[1], m[2] * e[2]), luts.transmittance);
    sun_xyz += m * e;
    const glsl::AtmosphereParameters& p = luts.parameters;
    for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
      extinction[i] += m * (e * p.extinction_profile[i]);
      mie[i] += m * (e * p.mie_scattering_profile[i]);
      rayleigh[i] += m * (e * p.rayleigh_scattering_profile[i]);
    }
  }
  out.irradiance = irradiance->Texture();
  out.scattering = scattering->Texture();
  out.single_mie_scattering = single_mie->Texture();
  out.transmittance = transmittance->Texture();
  out.parameters.solar_irradiance = sun_xyz;
  out.parameters.transmittance_is_colour = 1;
  auto per_sun = [&](const glsl::vec3& v) {
    glsl::vec3 r(0.0);
    for (int c = 0; c < 3; ++c) r[c] = sun_xyz[c] > 0.0 ? v[c] / sun_xyz[c] : 0.0;
    return r;
  };
  for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
    out.parameters.extinction_profile[i] = per_sun(extinction[i]);
    out.parameters.mie_scattering_profile[i] = per_sun(mie[i]);
    out.parameters.rayleigh_scattering_profile[i] = per_sun(rayleigh[i]);
  }
  if (report) *report = total;
  return out;
}

}  // namespace skybake
