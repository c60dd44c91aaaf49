// Spectral bakes: N wavelengths, computed three at a time by the
// three-channel bake and reference (one wavelength per channel), and
// combined into CIE 1931 XYZ in photometric units.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "core/spectrum.h"

namespace skybake {

// The maximum luminous efficacy K_m = 683 lm/W of CIE photometry: with it a
// spectral radiance in W m^-2 sr^-1 nm^-1 converts to XYZ whose Y is the
// luminance in cd m^-2 (an irradiance to XYZ whose Y is the illuminance, lux).
inline constexpr double kLuminousEfficacyLmPerW = 683.0;

// The CIE observer's range, over which a spectral bake spreads its wavelengths.
inline constexpr double kSpectralFirstNm = 360.0, kSpectralLastNm = 830.0;
inline constexpr int kDefaultSpectralWavelengths = 15;

// `count` (>= 3) wavelengths evenly from kSpectralFirstNm to kSpectralLastNm.
std::vector<double> SpectralWavelengths(int count);

// N wavelengths as batches of three (the channels of a three-wavelength bake)
// and, per batch, the matrix that adds its three values to XYZ:
// XYZ = sum over batches of to_xyz[b] * value_b is K_m times the integral of
// the spectrum, linear between the wavelengths and 0 outside them, against
// the colour-matching functions (SpectrumToXyz). Where N is not a multiple of
// three, the last batch repeats its last wavelength with a zero column.
struct SpectralBatches {
  std::vector<double> wavelengths_nm;        // the N wavelengths
  std::vector<Spectrum> batch_wavelengths_nm;
  std::vector<glm::dmat3> to_xyz;

  std::size_t size() const { return to_xyz.size(); }
};
SpectralBatches MakeSpectralBatches(const std::vector<double>& wavelengths_nm);

// A spectral bake: `atmosphere` read at each batch's wavelengths
// (ParseAtmosphere), baked with `settings`, and the batches' tables added in
// XYZ with their matrices:
// - irradiance, scattering and single Mie hold light, linear in the
//   spectrum, and their phase functions do not depend on the wavelength, so
//   the sums are the tables of the N-wavelength spectrum converted (the
//   run-time interpolation of the sums is where they can differ);
// - transmittance holds the optical depth of sunlight's colour,
//   -ln(XYZ of E T / XYZ of E) per channel, so that the sun's colour through
//   the atmosphere is exact at the texels; light from elsewhere (an object
//   behind aerial perspective) attenuates by the sun's spectrum's mean, an
//   approximation (docs/colour.md measures it);
// - the parameters' solar irradiance is the sun's XYZ, and the altitude
//   profiles of the aerial-perspective march are the coefficients averaged
//   over the sun's spectrum per channel, exact to first order in the
//   optical depth.
// The result's `atmosphere` is the file at its own three wavelengths (its
// geometry and constituents for the manifest); `colour` says the tables are
// XYZ. `progress` sees each batch's phases, named with the batch.
// InputError, before anything is baked, for settings a spectral bake cannot
// take (single Mie packed in the scattering table's alpha, a scattering
// range) and for an atmosphere not defined at every batch's wavelengths.
LutSet BakeSpectral(const AtmosphereSource& atmosphere, const SpectralBatches& batches, const BakeSettings& settings,
                    BakeReport* report = nullptr, const BakeProgress& progress = nullptr);

}  // namespace skybake
