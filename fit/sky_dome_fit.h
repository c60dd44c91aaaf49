// The sky-dome fit: samples each constituent's exact relative optical path
// m(θ, h) (optical_path.h) on a grid of zenith angles and observer altitudes,
// fits every candidate form (forms.h) with Ceres, keeps the one with the
// lowest maximum error on a denser validation grid, and measures Iqbal's
// formula on the same grids.
//
// Altitude range: the requested [min, max] is clipped to the atmosphere, and
// per constituent to the altitudes where at least `min_column_fraction` of
// its vertical column at the lowest altitude still lies above the observer.
// Above that (a fog layer below a high observer) the constituent's slant
// column is negligible whatever m is, and m itself tends to 0/0; the
// generated functions clamp the altitude to the fitted range.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "fit/forms.h"
#include "fit/quadrature.h"

namespace skybake::fit {

struct FitOptions {
  double altitude_min_m = 0.0;
  double altitude_max_m = 10000.0;
  // Candidate forms; every one is fitted and the best on the validation grid kept.
  std::vector<FormKind> forms = {FormKind::kChapmanChord, FormKind::kKasten};
  int fit_altitudes = 11;         // odd, so the nodes t = 0, 1/2, 1 are sampled
  int validation_altitudes = 21;  // includes the midpoints between fit altitudes
  double validation_zenith_step_deg = 0.25;
  double min_column_fraction = 1e-6;
  QuadratureOptions quadrature;
};

// The fitted surface: everything an evaluator needs.
struct Surface {
  FormKind form = FormKind::kChapmanChord;
  double altitude_lo_m = 0.0;
  double altitude_hi_m = 0.0;
  std::array<double, kCoefficientCount> coefficients{};

  // μ is clamped to [0, 1] and the altitude to [lo, hi].
  double RelativeOpticalPath(double mu, double altitude_m) const;
  double NormalizedAltitude(double altitude_m) const;
};

// Errors of a fitted relative optical path against the exact samples of a
// grid (not report::ErrorStats, which compares radiances with the reference).
struct OpticalPathErrors {
  int points = 0;
  double max_relative = 0.0;
  double rms_relative = 0.0;
  double max_relative_zenith_le_85 = 0.0;
  double worst_zenith_deg = 0.0;
  double worst_altitude_m = 0.0;
};

struct CandidateFit {
  Surface surface;
  OpticalPathErrors fit_grid, validation_grid;
  double final_cost = 0.0;
  int iterations = 0;
  std::string termination;
};

// Exact samples on a zenith × altitude grid (row-major: altitude outer).
struct SampleGrid {
  std::vector<double> zenith_deg;
  std::vector<double> altitude_m;
  std::vector<double> relative_optical_path;  // slant / vertical column
  int unconverged = 0;                        // quadratures that missed their tolerance
  double At(size_t altitude_index, size_t zenith_index) const {
    return relative_optical_path[altitude_index * zenith_deg.size() + zenith_index];
  }
};

struct ZenithOpticalLength {
  double altitude_m;
  std::optional<double> value_m;  // vertical column / density; empty where the density is 0
};

// Both ratios at one point, for the report (see optical_path.h).
struct OpticalPathSample {
  double zenith_deg;
  double altitude_m;
  double relative_optical_path;
  std::optional<double> optical_length_m;  // empty where the density at the observer is 0
};

struct ConstituentFit {
  std::string name;
  std::string identifier;  // GLSL/C++-safe, unique within the fit set
  bool fitted = false;
  std::string skip_reason;
  Surface surface;         // the kept candidate
  OpticalPathErrors fit_errors, validation_errors;
  OpticalPathErrors iqbal_fit_errors, iqbal_validation_errors;
  std::vector<CandidateFit> candidates;
  std::vector<ZenithOpticalLength> zenith_optical_length;  // at the fit altitudes
  std::vector<OpticalPathSample> samples;  // a few exact values at the lowest, middle and highest altitude
  int unconverged_samples = 0;
};

struct FitSet {
  std::string atmosphere_name;
  double bottom_radius_m = 0.0;
  double top_radius_m = 0.0;
  FitOptions options;
  std::vector<double> fit_zenith_deg;  // shared by every constituent
  std::vector<ConstituentFit> constituents;
  // Indices into `constituents`, -1 if absent: the first Rayleigh-phase
  // constituent ("air") and the first other scattering one ("haze").
  int air = -1;
  int haze = -1;
};

// The fit grid's zenith angles: 2° steps to 80°, 0.5° steps to 90°, where m
// changes fastest.
std::vector<double> FitZenithAngles();

// Samples m on the grid; altitudes with no column above are skipped by the
// callers (see the file comment), so every value here is finite.
SampleGrid SampleRelativeOpticalPath(const Atmosphere& atmosphere, const Constituent& constituent,
                                     const std::vector<double>& zenith_deg,
                                     const std::vector<double>& altitude_m,
                                     const QuadratureOptions& quadrature);

ConstituentFit FitConstituent(const Atmosphere& atmosphere, const Constituent& constituent,
                              const FitOptions& options);

// `names` empty: every constituent. An unknown name is an InputError; a
// constituent that cannot be fitted is kept with fitted = false and a reason.
// Zero constituents give an empty set, which is not an error. Throws
// InternalError if Ceres returns non-finite coefficients.
FitSet FitAtmosphere(const Atmosphere& atmosphere, const std::vector<std::string>& names,
                     const FitOptions& options,
                     const std::function<void(const std::string&)>& progress = {});

// Lower-case [a-z0-9_] identifier for generated code; unique against `taken`.
std::string MakeIdentifier(const std::string& name, const std::vector<std::string>& taken);

}  // namespace skybake::fit
