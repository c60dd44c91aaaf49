// Spectral bakes: N wavelengths, computed three at a time by the
// three-channel bake and reference (one wavelength per channel), and
// combined into CIE 1931 XYZ in photometric units.
#pragma once

#include <array>
#include <cstddef>
#include <glm/glm.hpp>
#include <string>
#include <vector>

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
// The colour-matching functions are tabulated every 5 nm (data/README.md):
// 95 wavelengths over 360-830 nm sample them at their own spacing, and more
// would only interpolate the data (and take minutes).
inline constexpr int kMaxSpectralWavelengths = 95;

// `count` (3 to kMaxSpectralWavelengths) wavelengths evenly from
// kSpectralFirstNm to kSpectralLastNm.
std::vector<double> SpectralWavelengths(int count);

// How a spectral bake computes the scattering orders >= 2 (docs/colour.md).
// Single scattering, the sun's transmittance and the sky light of single
// scattering on the ground are computed at every wavelength either way.
enum class SpectralHigherOrders {
  // At every wavelength.
  kExact,
  // At three wavelengths (kInterpolationAnchorsNm), and at the others
  // interpolated per texel by HigherOrderInterpolation: about half the time.
  kInterpolated,
};
// The wavelengths nearest to these compute the higher orders of an
// interpolated bake: 100 nm apart across the span where the colour-matching
// functions weigh most (z-bar peaks at 445 nm, y-bar at 555, x-bar at 600).
// Of the 48 triples of a 15-wavelength bake measured against the spectral
// reference, 44 meet every colour target; this one is within 0.01 % of the
// least daylight luminance error with the least colour error among those
// (docs/colour.md).
inline constexpr double kInterpolationAnchorsNm[3] = {460.0, 560.0, 660.0};
inline constexpr SpectralHigherOrders kDefaultSpectralHigherOrders = SpectralHigherOrders::kInterpolated;
// "interpolated" or "exact"; InputError otherwise.
SpectralHigherOrders ParseSpectralHigherOrders(const std::string& name);
const char* ToString(SpectralHigherOrders higher_orders);

// N wavelengths as batches of three (the channels of a three-wavelength bake)
// and, per batch, the matrix that adds its three values to XYZ:
// XYZ = sum over batches of to_xyz[b] * value_b is K_m times the integral of
// the spectrum, linear between the wavelengths and 0 outside them, against
// the colour-matching functions (SpectrumToXyz). Where N is not a multiple of
// three, the last batch repeats its last wavelength with a zero column.
// With kInterpolated, the wavelengths that compute the higher orders form
// the first batch and the others follow in order.
struct SpectralBatches {
  std::vector<double> wavelengths_nm;  // the N wavelengths, increasing
  std::vector<Spectrum> batch_wavelengths_nm;
  // Per batch and channel, the index into wavelengths_nm; -1 for a repeat.
  std::vector<std::array<int, kWavelengthCount>> wavelength_index;
  std::vector<glm::dmat3> to_xyz;
  // How many leading batches compute the higher orders (all for kExact).
  std::size_t higher_order_batches = 0;

  std::size_t size() const { return to_xyz.size(); }
  // The wavelengths (indices, increasing) whose higher orders are computed.
  std::vector<int> HigherOrderWavelengths() const;
};
SpectralBatches MakeSpectralBatches(const std::vector<double>& wavelengths_nm, SpectralHigherOrders higher_orders);

// The interpolation of the higher orders H (the scattering orders >= 2)
// across wavelengths. Per texel, with N a reference spectrum that carries
// what all orders share (the sun's spectrum, or the sky light of single
// scattering; BakeSpectral),
//   ln(H(lambda) / N(lambda)) = a + b ln s(lambda) + c tau(lambda),
// where s is the atmosphere's scattering coefficient at the ground and tau
// its vertical absorption optical depth: light scattered n times more gains
// about s^n and loses exp(-tau times the absorber's path), and a, b and c
// are the texel's, through the wavelengths whose H is computed. A basis
// function that these wavelengths cannot tell from the others (no absorber,
// a grey atmosphere) is left out, and what the rest leave at the computed
// wavelengths is interpolated linearly in wavelength between them (held
// beyond them). Both are linear in ln(H/N) at the computed wavelengths:
//   ln(H_i / N_i) = sum_j log_weight[i][j] ln(H_j / N_j),
// j over `computed` (log_weight[computed[j]] is the unit vector j). Where a
// texel's H is not positive at every computed wavelength, the linear
// interpolation of H / N in wavelength stands in:
//   H_i / N_i = sum_j linear_weight[i][j] H_j / N_j.
struct HigherOrderInterpolation {
  std::vector<std::vector<double>> log_weight, linear_weight;  // [wavelength][computed]
};
HigherOrderInterpolation MakeHigherOrderInterpolation(const std::vector<double>& wavelengths_nm,
                                                      const std::vector<int>& computed,
                                                      const std::vector<double>& ground_scattering,
                                                      const std::vector<double>& absorption_depth);

// A spectral bake: `atmosphere` read at each batch's wavelengths
// (ParseAtmosphere), baked with `settings` (the batches past
// higher_order_batches with single scattering and its sky light only, their
// higher orders interpolated), and the batches' tables added in XYZ with
// their matrices:
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
