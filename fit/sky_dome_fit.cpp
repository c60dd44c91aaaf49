#include "fit/sky_dome_fit.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>

#include <tbb/parallel_for.h>

#include "core/errors.h"
#include "fit/optical_path.h"
#include "fit/solver.h"

namespace skybake::fit {

namespace {

constexpr double kRadiansPerDegree = 0.017453292519943295769237;

double ZenithToMu(double zenith_deg) {
  // cos(90°) in floating point is 6e-17, not 0; the horizon is sampled exactly.
  return zenith_deg >= 90.0 ? 0.0 : std::cos(zenith_deg * kRadiansPerDegree);
}

std::vector<double> Linspace(double lo, double hi, int count) {
  if (count <= 1 || !(hi > lo)) return {lo};
  std::vector<double> v(count);
  for (int i = 0; i < count; ++i) v[i] = i + 1 == count ? hi : lo + (hi - lo) * i / (count - 1);
  return v;
}

OpticalPathErrors MeasureErrors(const SampleGrid& grid, const std::function<double(double, double)>& model) {
  OpticalPathErrors stats;
  double sum_sq = 0.0;
  for (size_t a = 0; a < grid.altitude_m.size(); ++a) {
    for (size_t z = 0; z < grid.zenith_deg.size(); ++z) {
      double exact = grid.At(a, z);
      double value = model(ZenithToMu(grid.zenith_deg[z]), grid.altitude_m[a]);
      // A non-finite model value counts as an infinite error rather than
      // vanishing from max() as NaN would.
      double error = std::isfinite(value) ? std::abs(value / exact - 1.0) : HUGE_VAL;
      ++stats.points;
      sum_sq += error * error;
      if (error > stats.max_relative) {
        stats.max_relative = error;
        stats.worst_zenith_deg = grid.zenith_deg[z];
        stats.worst_altitude_m = grid.altitude_m[a];
      }
      if (grid.zenith_deg[z] <= 85.0) stats.max_relative_zenith_le_85 = std::max(stats.max_relative_zenith_le_85, error);
    }
  }
  stats.rms_relative = stats.points ? std::sqrt(sum_sq / stats.points) : 0.0;
  return stats;
}

// ln ε at which the chapman-chord form with shape (a, b) has horizon value
// m90 = D(1)/D(0), found by bisection (the ratio falls monotonically with ε).
double ChordLnEpsilonForHorizon(double a, double b, double m90) {
  double lo = -60.0, hi = 60.0;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi), eps = std::exp(mid);
    double ratio = (1.0 + a * eps / (std::sqrt(1.0 + eps) + b)) / (a * std::sqrt(eps));
    (ratio > m90 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Starting points that reproduce the exact horizon values at the three
// nodes, for a few typical shapes and for a layer top far above the range
// and just above it.
std::vector<std::array<double, kCoefficientCount>> InitialGuesses(FormKind kind,
                                                                  const std::array<double, 3>& m90) {
  std::vector<std::array<double, kCoefficientCount>> guesses;
  std::vector<std::pair<double, double>> shapes;
  if (kind == FormKind::kChapmanChord) {
    // (a, b) of an exponential profile, a uniform slab and a thin elevated layer.
    shapes = {{0.275, 1.34}, {0.5, 1.0}, {1.0, 1.0}};
  } else {
    // (b, c): Iqbal's, and a flatter start.
    shapes = {{93.885, 1.253}, {91.0, 1.0}};
  }
  for (double ln_tau_minus_1 : {std::log(1000.0), std::log(0.1)}) {
    for (auto [s0, s1] : shapes) {
      std::array<double, kCoefficientCount> g{};
      g[kLayerTopCoefficient] = ln_tau_minus_1;
      for (int node = 0; node < 3; ++node) {
        double ln_to_top = std::log(1.0 - 0.5 * node + std::exp(ln_tau_minus_1));
        if (kind == FormKind::kChapmanChord) {
          g[node] = ChordLnEpsilonForHorizon(s0, s1, m90[node]) - ln_to_top;
          g[3 + node] = std::log(s0);
          g[6 + node] = std::log(s1);
        } else {
          g[node] = std::log(std::pow(s0 - 90.0, s1) / m90[node]) - 0.5 * ln_to_top;
          g[3 + node] = std::log(s0 - 90.0);
          g[6 + node] = std::log(s1);
        }
      }
      guesses.push_back(g);
    }
  }
  return guesses;
}

}  // namespace

double Surface::NormalizedAltitude(double altitude_m) const {
  if (!(altitude_hi_m > altitude_lo_m)) return 0.0;
  return std::clamp((altitude_m - altitude_lo_m) / (altitude_hi_m - altitude_lo_m), 0.0, 1.0);
}

double Surface::RelativeOpticalPath(double mu, double altitude_m) const {
  return EvaluateForm(form, coefficients.data(), std::clamp(mu, 0.0, 1.0), NormalizedAltitude(altitude_m));
}

std::vector<double> FitZenithAngles() {
  std::vector<double> z;
  for (int i = 0; i <= 40; ++i) z.push_back(2.0 * i);
  for (int i = 1; i <= 20; ++i) z.push_back(80.0 + 0.5 * i);
  return z;
}

SampleGrid SampleRelativeOpticalPath(const Atmosphere& atmosphere, const Constituent& constituent,
                                     const std::vector<double>& zenith_deg,
                                     const std::vector<double>& altitude_m,
                                     const QuadratureOptions& quadrature) {
  ColumnIntegrator integrator(constituent.density, atmosphere.bottom_radius_m, atmosphere.top_radius_m,
                              quadrature);
  SampleGrid grid;
  grid.zenith_deg = zenith_deg;
  grid.altitude_m = altitude_m;
  grid.relative_optical_path.assign(zenith_deg.size() * altitude_m.size(), 0.0);
  std::vector<double> vertical(altitude_m.size());
  std::atomic<int> unconverged{0};
  for (size_t a = 0; a < altitude_m.size(); ++a) {
    QuadratureResult v = integrator.VerticalColumn(altitude_m[a]);
    if (!(v.value > 0.0)) {
      throw InternalError("constituent '" + constituent.name + "' has no column above the sampled altitude " +
                          std::to_string(altitude_m[a]) + " m");
    }
    vertical[a] = v.value;
    if (!v.converged) ++unconverged;
  }
  tbb::parallel_for(size_t{0}, grid.relative_optical_path.size(), [&](size_t i) {
    size_t a = i / zenith_deg.size(), z = i % zenith_deg.size();
    QuadratureResult slant = integrator.SlantColumn(altitude_m[a], ZenithToMu(zenith_deg[z]));
    if (!slant.converged) ++unconverged;
    grid.relative_optical_path[i] = slant.value / vertical[a];
  });
  grid.unconverged = unconverged;
  return grid;
}

ConstituentFit FitConstituent(const Atmosphere& atmosphere, const Constituent& constituent,
                              const FitOptions& options) {
  ConstituentFit result;
  result.name = constituent.name;
  ColumnIntegrator integrator(constituent.density, atmosphere.bottom_radius_m, atmosphere.top_radius_m,
                              options.quadrature);
  double thickness = integrator.thickness_m();
  if (options.altitude_min_m > thickness) {
    result.skip_reason = "the observer altitudes lie above the top of the atmosphere";
    return result;
  }
  double lo = std::clamp(options.altitude_min_m, 0.0, thickness);
  double hi = std::clamp(options.altitude_max_m, lo, thickness);
  double column_lo = integrator.VerticalColumn(lo).value;
  if (!(column_lo > 0.0)) {
    result.skip_reason = "no density above the lowest observer altitude";
    return result;
  }
  // Clip the range where the column above the observer becomes negligible
  // (the column falls monotonically with altitude, so bisection finds it).
  double threshold = options.min_column_fraction * column_lo;
  if (!(integrator.VerticalColumn(hi).value >= threshold)) {
    double below = lo, above = hi;
    for (int i = 0; i < 100 && above - below > 1e-9 * std::max(1.0, above); ++i) {
      double mid = 0.5 * (below + above);
      (integrator.VerticalColumn(mid).value >= threshold ? below : above) = mid;
    }
    hi = below;
  }
  // A range of a few nanometres is one altitude for every practical purpose.
  if (hi - lo < 1e-9 * std::max(1.0, hi)) hi = lo;

  std::vector<double> fit_altitudes = Linspace(lo, hi, std::max(1, options.fit_altitudes | 1));
  std::vector<double> validation_altitudes = Linspace(lo, hi, std::max(1, options.validation_altitudes));
  std::vector<double> validation_zenith;
  int steps = static_cast<int>(std::ceil(90.0 / options.validation_zenith_step_deg - 1e-9));
  for (int i = 0; i <= steps; ++i) validation_zenith.push_back(std::min(90.0, i * 90.0 / steps));

  SampleGrid fit_grid = SampleRelativeOpticalPath(atmosphere, constituent, FitZenithAngles(), fit_altitudes,
                                                  options.quadrature);
  SampleGrid validation_grid = SampleRelativeOpticalPath(atmosphere, constituent, validation_zenith,
                                                         validation_altitudes, options.quadrature);
  result.unconverged_samples = fit_grid.unconverged + validation_grid.unconverged;

  FitSamples samples;
  for (size_t a = 0; a < fit_altitudes.size(); ++a) {
    double t = hi > lo ? (fit_altitudes[a] - lo) / (hi - lo) : 0.0;
    for (size_t z = 0; z < fit_grid.zenith_deg.size(); ++z) {
      samples.mu.push_back(ZenithToMu(fit_grid.zenith_deg[z]));
      samples.t.push_back(t);
      samples.ln_target.push_back(std::log(fit_grid.At(a, z)));
    }
  }
  // Horizon values at the nodes t = 0, 1/2, 1 seed the initial guesses.
  std::array<double, 3> m90;
  size_t horizon = fit_grid.zenith_deg.size() - 1;
  for (int node = 0; node < 3; ++node) {
    size_t a = static_cast<size_t>(std::lround(node * 0.5 * (fit_altitudes.size() - 1)));
    m90[node] = fit_grid.At(a, horizon);
  }

  std::string failures;
  for (FormKind form : options.forms) {
    SolverResult solved = SolveForm(form, samples, InitialGuesses(form, m90), fit_altitudes.size() == 1);
    if (!solved.usable) {
      failures += std::string(failures.empty() ? "" : "; ") + ToString(form) + ": " + solved.termination;
      continue;
    }
    CandidateFit candidate;
    candidate.surface = Surface{form, lo, hi, solved.coefficients};
    auto model = [&](double mu, double h) { return candidate.surface.RelativeOpticalPath(mu, h); };
    candidate.fit_grid = MeasureErrors(fit_grid, model);
    candidate.validation_grid = MeasureErrors(validation_grid, model);
    candidate.final_cost = solved.final_cost;
    candidate.iterations = solved.iterations;
    candidate.termination = solved.termination;
    if (!std::isfinite(candidate.validation_grid.max_relative)) {
      failures += std::string(failures.empty() ? "" : "; ") + ToString(form) + ": non-finite values";
      continue;
    }
    result.candidates.push_back(candidate);
  }
  if (result.candidates.empty()) {
    throw InternalError("the fit of constituent '" + constituent.name + "' failed (" +
                        (failures.empty() ? std::string("no candidate forms") : failures) + ")");
  }
  const CandidateFit& best = *std::min_element(
      result.candidates.begin(), result.candidates.end(), [](const CandidateFit& x, const CandidateFit& y) {
        return x.validation_grid.max_relative < y.validation_grid.max_relative;
      });
  result.fitted = true;
  result.surface = best.surface;
  result.fit_errors = best.fit_grid;
  result.validation_errors = best.validation_grid;
  auto iqbal = [](double mu, double) { return IqbalRelativeOpticalPath(mu); };
  result.iqbal_fit_errors = MeasureErrors(fit_grid, iqbal);
  result.iqbal_validation_errors = MeasureErrors(validation_grid, iqbal);
  for (double h : fit_altitudes) {
    ColumnSample zenith = integrator.Sample(h, 1.0);
    result.zenith_optical_length.push_back({h, zenith.OpticalLength()});
  }
  for (double h : {lo, 0.5 * (lo + hi), hi}) {
    for (double zenith : {0.0, 30.0, 60.0, 75.0, 80.0, 85.0, 88.0, 90.0}) {
      ColumnSample sample = integrator.Sample(h, ZenithToMu(zenith));
      result.samples.push_back({zenith, h, sample.RelativeOpticalPath().value_or(0.0), sample.OpticalLength()});
    }
    if (hi == lo) break;
  }
  return result;
}

std::string MakeIdentifier(const std::string& name, const std::vector<std::string>& taken) {
  std::string id;
  for (char ch : name) {
    char c = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    bool ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (ok) id += c;
    else if (!id.empty() && id.back() != '_') id += '_';  // GLSL reserves "__"
  }
  while (!id.empty() && id.back() == '_') id.pop_back();
  if (id.empty() || (id[0] >= '0' && id[0] <= '9')) id = "c" + id;
  std::string unique = id;
  for (int n = 2; std::find(taken.begin(), taken.end(), unique) != taken.end(); ++n)
    unique = id + "_" + std::to_string(n);
  return unique;
}

FitSet FitAtmosphere(const Atmosphere& atmosphere, const std::vector<std::string>& names,
                     const FitOptions& options, const std::function<void(const std::string&)>& progress) {
  if (!(std::isfinite(options.altitude_min_m) && std::isfinite(options.altitude_max_m) &&
        options.altitude_min_m >= 0.0 && options.altitude_max_m >= options.altitude_min_m)) {
    throw InputError("observer altitude range must satisfy 0 <= min <= max (got " +
                     std::to_string(options.altitude_min_m) + " .. " + std::to_string(options.altitude_max_m) +
                     " m)");
  }
  if (options.forms.empty()) throw InputError("no candidate forms to fit");
  if (!(options.validation_zenith_step_deg > 0.0 && options.validation_zenith_step_deg <= 90.0))
    throw InputError("validation zenith step must lie in (0, 90] degrees");
  for (const std::string& n : names) {
    bool known = std::any_of(atmosphere.constituents.begin(), atmosphere.constituents.end(),
                             [&](const Constituent& c) { return c.name == n; });
    if (!known) {
      std::string list;
      for (const Constituent& c : atmosphere.constituents) list += (list.empty() ? "" : ", ") + c.name;
      throw InputError("unknown constituent '" + n + "' (" + atmosphere.name + " has: " +
                       (list.empty() ? "none" : list) + ")");
    }
  }

  FitSet set;
  set.atmosphere_name = atmosphere.name;
  set.bottom_radius_m = atmosphere.bottom_radius_m;
  set.top_radius_m = atmosphere.top_radius_m;
  set.options = options;
  set.fit_zenith_deg = FitZenithAngles();
  std::vector<std::string> taken;
  for (const Constituent& constituent : atmosphere.constituents) {
    if (!names.empty() && std::find(names.begin(), names.end(), constituent.name) == names.end()) continue;
    if (progress) progress(constituent.name);
    ConstituentFit fit = FitConstituent(atmosphere, constituent, options);
    fit.identifier = MakeIdentifier(constituent.name, taken);
    taken.push_back(fit.identifier);
    int index = static_cast<int>(set.constituents.size());
    bool scatters = constituent.scattering_per_m.x > 0.0 || constituent.scattering_per_m.y > 0.0 ||
                    constituent.scattering_per_m.z > 0.0;
    if (fit.fitted && constituent.phase.kind == PhaseKind::kRayleigh && set.air < 0) set.air = index;
    if (fit.fitted && constituent.phase.kind != PhaseKind::kRayleigh && scatters && set.haze < 0)
      set.haze = index;
    set.constituents.push_back(std::move(fit));
  }
  return set;
}

}  // namespace skybake::fit
