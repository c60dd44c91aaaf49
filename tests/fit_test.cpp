// Tests of the sky-dome fit: quadrature against closed forms, the exact
// relative optical path against the Chapman asymptote, fit accuracy against
// Iqbal's formula, finiteness on presets and extreme atmospheres.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bake/atmosphere.h"
#include "bake/errors.h"
#include "fit/forms.h"
#include "fit/optical_path.h"
#include "fit/quadrature.h"
#include "fit/sky_dome_fit.h"
#include "fit/solver.h"

namespace skybake::fit {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.14159265358979323846;
constexpr double kEarthRadius = 6360e3;
constexpr double kEarthTop = 6420e3;

// ---- density profiles ----

DensityProfile Exponential(double scale_height_m) {
  DensityProfile p;
  p.layers.push_back({0.0, 1.0, -1.0 / scale_height_m, 0.0, 0.0});
  return p;
}

DensityProfile Constant(double density) {
  DensityProfile p;
  p.layers.push_back({0.0, 0.0, 0.0, 0.0, density});
  return p;
}

DensityProfile Slab(double thickness_m) {
  DensityProfile p;
  p.layers.push_back({thickness_m, 0.0, 0.0, 0.0, 1.0});
  p.layers.push_back({0.0, 0.0, 0.0, 0.0, 0.0});
  return p;
}

// 0 below 10 km, rising linearly to 1 at 25 km, back to 0 at 40 km.
DensityProfile OzoneTent() {
  DensityProfile p;
  p.layers.push_back({25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0});
  p.layers.push_back({0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0});
  return p;
}

double Mu(double zenith_deg) { return zenith_deg >= 90.0 ? 0.0 : std::cos(zenith_deg * kPi / 180.0); }

// ---- quadrature ----

TEST(Quadrature, SevenPointGaussAndFifteenPointKronrodAreExactForPolynomials) {
  // G7 integrates degree <= 13 exactly, so the error estimate vanishes and no
  // panel is split; the K15 value must equal 1/(k+1) to rounding.
  for (int k = 0; k <= 13; ++k) {
    QuadratureResult r = Integrate([k](double x) { return std::pow(x, k); }, 0.0, 1.0);
    EXPECT_NEAR(r.value, 1.0 / (k + 1), 1e-15) << "x^" << k;
    EXPECT_EQ(r.panels, 1) << "x^" << k;
  }
}

TEST(Quadrature, ForcedBreakpointsMakeJumpsExact) {
  auto step = [](double x) { return x < 0.3 ? 1.0 : 2.0; };
  QuadratureResult r = Integrate(step, 0.0, 1.0, {0.3, -5.0, 7.0, 0.3});
  EXPECT_NEAR(r.value, 1.7, 1e-15);
  EXPECT_EQ(r.panels, 2);
}

TEST(Quadrature, MeetsItsRelativeTolerance) {
  QuadratureResult e = Integrate([](double x) { return std::exp(-x); }, 0.0, 50.0);
  EXPECT_TRUE(e.converged);
  EXPECT_NEAR(e.value / -std::expm1(-50.0), 1.0, 1e-9);
  QuadratureResult s = Integrate([](double x) { return std::sqrt(x); }, 0.0, 1.0);
  EXPECT_TRUE(s.converged);
  EXPECT_NEAR(s.value * 1.5, 1.0, 1e-9);
}

TEST(Quadrature, ReportsWhenItRunsOutOfPanels) {
  QuadratureOptions tight;
  tight.max_panels = 8;
  QuadratureResult r = Integrate([](double x) { return 1.0 / std::sqrt(x); }, 0.0, 1.0, {}, tight);
  EXPECT_FALSE(r.converged);
  EXPECT_TRUE(std::isfinite(r.value));
}

// ---- exact columns ----

TEST(OpticalPath, VerticalColumnOfAnExponentialMatchesTheClosedForm) {
  // Column above h: H e^(-h/H) (1 - e^(-(top-h)/H)); divided by the density
  // at h it is the zenith optical length H (1 - e^(-(top-h)/H)).
  for (double scale : {8000.0, 1200.0, 50.0}) {
    ColumnIntegrator integrator(Exponential(scale), kEarthRadius, kEarthTop);
    for (double h : {0.0, 1000.0, 10000.0, 59000.0}) {
      if (h / scale > 600.0) continue;  // e^(-h/H) underflows
      double length = -scale * std::expm1(-(60e3 - h) / scale);
      EXPECT_NEAR(integrator.VerticalColumn(h).value / (std::exp(-h / scale) * length), 1.0, 1e-8)
          << "H=" << scale << " h=" << h;
      ColumnSample zenith = integrator.Sample(h, 1.0);
      ASSERT_TRUE(zenith.OpticalLength());
      EXPECT_NEAR(*zenith.OpticalLength() / length, 1.0, 1e-8) << "H=" << scale << " h=" << h;
    }
  }
}

// Chord through the shell from radius r to the top, in long double and the
// textbook form, independent of the integrator's cancellation-free form.
long double Chord(long double r, long double mu, long double top) {
  return std::sqrt(r * r * mu * mu + top * top - r * r) - r * mu;
}

TEST(OpticalPath, SlantColumnOfConstantDensityIsTheChordLength) {
  ColumnIntegrator integrator(Constant(1.0), kEarthRadius, kEarthTop);
  for (double h : {0.0, 5000.0, 59000.0}) {
    for (double zenith : {0.0, 30.0, 60.0, 85.0, 89.9, 90.0}) {
      long double expected = Chord(kEarthRadius + h, Mu(zenith), kEarthTop);
      double got = integrator.SlantColumn(h, Mu(zenith)).value;
      EXPECT_NEAR(got / static_cast<double>(expected), 1.0, 1e-8) << "h=" << h << " zenith=" << zenith;
    }
  }
}

TEST(OpticalPath, SlantColumnAcrossADensityJumpIsExact) {
  // Density 1 up to 2 km, 0.25 above: 0.75 * chord(2 km) + 0.25 * chord(top).
  DensityProfile p;
  p.layers = {{2000.0, 0.0, 0.0, 0.0, 1.0}, {0.0, 0.0, 0.0, 0.0, 0.25}};
  ColumnIntegrator integrator(p, kEarthRadius, kEarthTop);
  for (double h : {0.0, 1500.0}) {
    for (double zenith : {0.0, 45.0, 80.0, 90.0}) {
      long double r = kEarthRadius + h;
      long double expected = 0.75L * Chord(r, Mu(zenith), kEarthRadius + 2000.0L) + 0.25L * Chord(r, Mu(zenith), kEarthTop);
      EXPECT_NEAR(integrator.SlantColumn(h, Mu(zenith)).value / static_cast<double>(expected), 1.0, 1e-8)
          << "h=" << h << " zenith=" << zenith;
    }
  }
}

TEST(OpticalPath, OzoneTentColumnAndClampKinks) {
  ColumnIntegrator integrator(OzoneTent(), kEarthRadius, kEarthTop);
  // A triangle 30 km wide and 1 high.
  EXPECT_NEAR(integrator.VerticalColumn(0.0).value / 15000.0, 1.0, 1e-8);
  // The clamp points 10 and 40 km are found besides the 25 km layer boundary.
  std::vector<double> expected = {10000.0, 25000.0, 40000.0};
  ASSERT_EQ(integrator.kinks().size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(integrator.kinks()[i], expected[i], 1e-6);
}

TEST(OpticalPath, HorizonValueMatchesTheChapmanAsymptote) {
  // m(90°, 0) of an exponential atmosphere tends to sqrt(πR/2H)(1 + 3H/8R)
  // for R ≫ H. With Earth's 60 km top the missing tail (e^-7.5 = 5.5e-4 of
  // both columns) keeps agreement at the 1e-3 level; a 400 km top removes
  // it (e^-50) and leaves the next series term, ~1e-7 at x = R/H = 795.
  const double R = kEarthRadius, H = 8000.0;
  double asymptote = std::sqrt(kPi * R / (2.0 * H)) * (1.0 + 3.0 * H / (8.0 * R));
  for (auto [top, tolerance] : {std::pair{kEarthTop, 1e-3}, std::pair{kEarthRadius + 400e3, 1e-5}}) {
    ColumnIntegrator integrator(Exponential(H), R, top);
    std::optional<double> m = integrator.Sample(0.0, 0.0).RelativeOpticalPath();
    ASSERT_TRUE(m);
    EXPECT_NEAR(*m / asymptote, 1.0, tolerance) << "top " << top;
  }
}

TEST(OpticalPath, GrazingRayAgreesWithBruteForceSimpson) {
  // An independent integrator: composite Simpson in path length with 2e6
  // panels in long double (error ~ (L/N)^4, far below 1e-10 here).
  const double H = 1200.0, h = 1000.0, mu = Mu(89.5);
  ColumnIntegrator integrator(Exponential(H), kEarthRadius, kEarthTop);
  long double r = kEarthRadius + h, length = Chord(r, mu, kEarthTop);
  auto density = [&](long double s) {
    long double z = std::sqrt(r * r + s * s + 2 * r * mu * s) - kEarthRadius;
    return std::exp(-z / H);
  };
  const int n = 2000000;
  long double step = length / n, sum = density(0) + density(length);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * density(i * step);
  long double simpson = sum * step / 3;
  EXPECT_NEAR(integrator.SlantColumn(h, mu).value / static_cast<double>(simpson), 1.0, 1e-9);
}

TEST(OpticalPath, ZeroDensityAtTheObserverFallsBackToTheRelativePath) {
  ColumnIntegrator integrator(OzoneTent(), kEarthRadius, kEarthTop);
  ColumnSample zenith = integrator.Sample(0.0, 1.0), horizon = integrator.Sample(0.0, 0.0);
  EXPECT_FALSE(zenith.OpticalLength().has_value());  // slant / 0: undefined
  ASSERT_TRUE(zenith.RelativeOpticalPath().has_value());
  EXPECT_NEAR(*zenith.RelativeOpticalPath(), 1.0, 1e-9);
  ASSERT_TRUE(horizon.RelativeOpticalPath().has_value());
  EXPECT_GT(*horizon.RelativeOpticalPath(), 1.0);
  EXPECT_TRUE(std::isfinite(*horizon.RelativeOpticalPath()));
}

TEST(OpticalPath, RaysBelowTheHorizonAreClampedAndEmptyColumnsReported) {
  ColumnIntegrator integrator(Exponential(8000.0), kEarthRadius, kEarthTop);
  EXPECT_EQ(integrator.SlantColumn(100.0, -0.5).value, integrator.SlantColumn(100.0, 0.0).value);
  ColumnIntegrator fog(Slab(200.0), kEarthRadius, kEarthTop);
  EXPECT_FALSE(fog.Sample(500.0, 0.3).RelativeOpticalPath().has_value());  // nothing above: 0/0
  EXPECT_THROW(ColumnIntegrator(Constant(1.0), 1000.0, 1000.0), InputError);
}

// ---- atmospheres built in code (DESIGN.md values) ----

Constituent MakeConstituent(const std::string& name, DensityProfile density, Spectrum scattering,
                            Spectrum absorption, PhaseKind phase, double g = 0.0) {
  Constituent c;
  c.name = name;
  c.density = std::move(density);
  c.scattering_per_m = scattering;
  c.absorption_per_m = absorption;
  c.phase = {phase, g};
  return c;
}

Atmosphere Planet(const std::string& name, double bottom, double top) {
  Atmosphere a;
  a.name = name;
  a.bottom_radius_m = bottom;
  a.top_radius_m = top;
  return a;
}

Constituent Rayleigh(double scale_height_m = 8000.0) {
  return MakeConstituent("rayleigh", Exponential(scale_height_m), {5.802e-6, 13.558e-6, 33.100e-6}, Spectrum(0.0),
                         PhaseKind::kRayleigh);
}

Atmosphere Earth() {
  Atmosphere a = Planet("earth", kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(),
                    MakeConstituent("mie", Exponential(1200.0), Spectrum(3.996e-6), Spectrum(0.444e-6),
                                    PhaseKind::kCornetteShanks, 0.8),
                    MakeConstituent("ozone", OzoneTent(), Spectrum(0.0), {0.650e-6, 1.881e-6, 0.085e-6},
                                    PhaseKind::kIsotropic)};
  return a;
}

Atmosphere EarthClear2008() {
  Atmosphere a = Planet("earth-clear-2008", kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(), MakeConstituent("mie", Exponential(1200.0), Spectrum(2e-5), Spectrum(2e-5 / 0.9 - 2e-5),
                                                PhaseKind::kCornetteShanks, 0.76)};
  return a;
}

// Hoffman & Preetham's haze table. How the config branch will shape the haze
// is not settled, so both a 1.25 km constant-density slab (their constant
// haze with its 1.25 km zenith optical length) and an exponential with a
// 1.25 km scale height are covered.
Atmosphere Haze(const std::string& name, Spectrum scattering, bool slab) {
  Atmosphere a = Planet(name + (slab ? "" : "-exponential"), kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(), MakeConstituent("haze", slab ? Slab(1250.0) : Exponential(1250.0), scattering,
                                                Spectrum(0.0), PhaseKind::kHenyeyGreenstein, 0.8)};
  return a;
}

Atmosphere Mars() {
  Atmosphere a = Planet("mars", 3389.5e3, 3389.5e3 + 80e3);
  a.constituents = {MakeConstituent("co2", Exponential(11000.0), {19.918e-6, 13.57e-6, 5.75e-6}, Spectrum(0.0),
                                    PhaseKind::kRayleigh),
                    MakeConstituent("dust", Exponential(3100.0), Spectrum(53.6e-6), Spectrum(53.6e-6 / 0.99 - 53.6e-6),
                                    PhaseKind::kHenyeyGreenstein, 0.85)};
  return a;
}

std::vector<Atmosphere> Presets() {
  std::vector<Atmosphere> presets = {Earth(), EarthClear2008(), Mars()};
  for (bool slab : {true, false}) {
    presets.push_back(Haze("light-haze", {2e-5, 3e-5, 4e-5}, slab));
    presets.push_back(Haze("heavy-haze", {8e-5, 1e-4, 1.2e-4}, slab));
    presets.push_back(Haze("light-fog", {9e-4, 1e-3, 1.1e-3}, slab));
    presets.push_back(Haze("heavy-fog", {1e-2, 1e-2, 1e-2}, slab));
  }
  return presets;
}

Atmosphere SingleExponential(double scale_height_m, double top = kEarthTop) {
  Atmosphere a = Planet("exponential", kEarthRadius, top);
  a.constituents = {MakeConstituent("air", Exponential(scale_height_m), Spectrum(1e-5), Spectrum(0.0),
                                    PhaseKind::kRayleigh)};
  return a;
}

// ---- the fit ----

struct GridErrors {
  double max_le_85 = 0.0, max_all = 0.0, iqbal_max = 0.0;
};

// Errors of a fitted surface and of Iqbal's formula against the exact
// integral on a grid independent of the fit's own grids: 0.1° steps and
// 250 m altitude steps.
GridErrors IndependentErrors(const Atmosphere& atmosphere, const Surface& surface, double h_max) {
  ColumnIntegrator integrator(atmosphere.constituents[0].density, atmosphere.bottom_radius_m, atmosphere.top_radius_m);
  GridErrors e;
  for (double h = 0.0; h <= h_max + 1e-9; h += 250.0) {
    for (int i = 0; i <= 900; ++i) {
      double zenith = 0.1 * i, mu = Mu(zenith);
      double exact = *integrator.Sample(h, mu).RelativeOpticalPath();
      double error = std::abs(surface.RelativeOpticalPath(mu, h) / exact - 1.0);
      e.max_all = std::max(e.max_all, error);
      if (zenith <= 85.0) e.max_le_85 = std::max(e.max_le_85, error);
      e.iqbal_max = std::max(e.iqbal_max, std::abs(IqbalRelativeOpticalPath(mu) / exact - 1.0));
    }
  }
  return e;
}

class ExponentialFit : public ::testing::TestWithParam<double> {};

TEST_P(ExponentialFit, IsAccurateAndBeatsIqbal) {
  // The bars (0.5% to 85°, 2% to 90°, 5x better than Iqbal) are what a sky
  // dome needs; the fit's measured errors are ~10x below them.
  Atmosphere atmosphere = SingleExponential(GetParam());
  FitSet set = FitAtmosphere(atmosphere, {}, FitOptions{});
  ASSERT_EQ(set.constituents.size(), 1u);
  const ConstituentFit& fit = set.constituents[0];
  ASSERT_TRUE(fit.fitted) << fit.skip_reason;
  EXPECT_EQ(fit.surface.altitude_hi_m, 10000.0);
  GridErrors e = IndependentErrors(atmosphere, fit.surface, 10000.0);
  std::cout << "H = " << GetParam() << " m: fit (" << ToString(fit.surface.form) << ") max error " << e.max_le_85
            << " (zenith <= 85), " << e.max_all << " (<= 90); Iqbal " << e.iqbal_max << "\n";
  EXPECT_LE(e.max_le_85, 0.005);
  EXPECT_LE(e.max_all, 0.02);
  EXPECT_GE(e.iqbal_max, 5.0 * e.max_all);
  EXPECT_EQ(fit.unconverged_samples, 0);
}

INSTANTIATE_TEST_SUITE_P(ScaleHeights, ExponentialFit, ::testing::Values(8000.0, 1200.0));

TEST(Fit, ChapmanChordFormBeatsKastenOnAnExponential) {
  // The evidence behind the default form: both are fitted with the same
  // parameter budget; the Chapman-based form has the lower validation error.
  FitSet set = FitAtmosphere(SingleExponential(8000.0), {}, FitOptions{});
  const ConstituentFit& fit = set.constituents.at(0);
  ASSERT_EQ(fit.candidates.size(), 2u);
  const CandidateFit& chord = fit.candidates[0];
  const CandidateFit& kasten = fit.candidates[1];
  ASSERT_EQ(chord.surface.form, FormKind::kChapmanChord);
  ASSERT_EQ(kasten.surface.form, FormKind::kKasten);
  EXPECT_LT(chord.validation_grid.max_relative, kasten.validation_grid.max_relative);
  EXPECT_EQ(fit.surface.form, FormKind::kChapmanChord);
}

TEST(Fit, ChapmanChordFormIsExactForAConstantDensitySlab) {
  // m of a uniform slab of thickness T - h seen from h is the chord ratio
  // (2r + T')/(rμ + sqrt(r²μ² + 2rT' + T'²)), which the form contains (a = 1/2,
  // b = 1, ε ∝ T - h): the fit must find it to rounding, up to the slab top.
  Atmosphere atmosphere = Planet("slab", kEarthRadius, kEarthTop);
  atmosphere.constituents = {MakeConstituent("fog", Slab(1250.0), Spectrum(1e-3), Spectrum(0.0),
                                             PhaseKind::kHenyeyGreenstein, 0.8)};
  FitSet set = FitAtmosphere(atmosphere, {}, FitOptions{});
  const ConstituentFit& fit = set.constituents.at(0);
  ASSERT_TRUE(fit.fitted);
  EXPECT_EQ(fit.surface.form, FormKind::kChapmanChord);
  EXPECT_LT(fit.validation_errors.max_relative, 1e-6);
  EXPECT_GT(fit.surface.altitude_hi_m, 1249.0);  // the range stops where the column vanishes
  EXPECT_LE(fit.surface.altitude_hi_m, 1250.0);
}

void ExpectFinite(const ErrorStats& e, const std::string& what) {
  EXPECT_TRUE(std::isfinite(e.max_relative) && std::isfinite(e.rms_relative) &&
              std::isfinite(e.max_relative_zenith_le_85))
      << what;
}

// Everything the fit produces for `atmosphere` is finite: coefficients and
// errors.
void ExpectAllFinite(const Atmosphere& atmosphere, const FitSet& set) {
  for (const ConstituentFit& c : set.constituents) {
    if (!c.fitted) {
      EXPECT_FALSE(c.skip_reason.empty()) << c.name;
      continue;
    }
    for (double v : c.surface.coefficients) EXPECT_TRUE(std::isfinite(v)) << atmosphere.name << "/" << c.name;
    EXPECT_TRUE(std::isfinite(c.surface.altitude_lo_m) && std::isfinite(c.surface.altitude_hi_m));
    ExpectFinite(c.fit_errors, c.name);
    ExpectFinite(c.validation_errors, c.name);
    ExpectFinite(c.iqbal_validation_errors, c.name);
    for (double zenith : {0.0, 45.0, 89.9, 90.0}) {
      for (double h : {c.surface.altitude_lo_m, c.surface.altitude_hi_m, 1e9}) {
        double m = c.surface.RelativeOpticalPath(Mu(zenith), h);
        EXPECT_TRUE(std::isfinite(m) && m > 0.0) << atmosphere.name << "/" << c.name << " m=" << m;
      }
    }
    for (const OpticalPathSample& s : c.samples) {
      EXPECT_TRUE(std::isfinite(s.relative_optical_path));
      if (s.optical_length_m) {
        EXPECT_TRUE(std::isfinite(*s.optical_length_m));
      }
    }
  }
}

TEST(Fit, EveryPresetFitsWithFiniteSmallErrors) {
  for (const Atmosphere& atmosphere : Presets()) {
    FitSet set = FitAtmosphere(atmosphere, {}, FitOptions{});
    ASSERT_EQ(set.constituents.size(), atmosphere.constituents.size());
    ExpectAllFinite(atmosphere, set);
    for (const ConstituentFit& c : set.constituents) {
      ASSERT_TRUE(c.fitted) << atmosphere.name << "/" << c.name << ": " << c.skip_reason;
      EXPECT_EQ(c.unconverged_samples, 0) << atmosphere.name << "/" << c.name;
      // 1% is the dome's error budget; measured: at most 0.3% (the ozone tent).
      EXPECT_LT(c.validation_errors.max_relative, 0.01) << atmosphere.name << "/" << c.name;
      EXPECT_LT(c.validation_errors.max_relative, c.iqbal_validation_errors.max_relative)
          << atmosphere.name << "/" << c.name;
    }
    EXPECT_GE(set.air, 0) << atmosphere.name;
  }
}

TEST(Fit, ExtremeAtmospheresStayFinite) {
  std::vector<Atmosphere> extremes;
  {
    Atmosphere a = Planet("one-metre-thick", kEarthRadius, kEarthRadius + 1.0);
    a.constituents = {Rayleigh(), MakeConstituent("thin", Exponential(0.1), Spectrum(1e-3), Spectrum(0.0),
                                                  PhaseKind::kHenyeyGreenstein, 0.5)};
    extremes.push_back(a);
  }
  {
    Atmosphere a = Planet("one-kilometre-planet", 1000.0, 61000.0);
    a.constituents = Earth().constituents;
    extremes.push_back(a);
  }
  {
    Atmosphere a = Planet("vacuum-gaps", kEarthRadius, kEarthTop);
    DensityProfile gaps;
    gaps.layers = {{2000.0, 0, 0, 0, 1.0}, {3000.0, 0, 0, 0, 0.0}, {3000.0, 0, 0, 0, 0.5}, {0.0, 0, 0, 0, 0.0}};
    DensityProfile tabulated;
    tabulated.kind = DensityProfile::Kind::kTabulated;
    tabulated.altitudes_m = {0.0, 1000.0, 1001.0, 4000.0, 4500.0};
    tabulated.densities = {0.0, 0.0, 1.0, 1.0, 0.0};
    a.constituents = {Rayleigh(), MakeConstituent("layers", gaps, Spectrum(1e-5), Spectrum(0.0), PhaseKind::kHenyeyGreenstein, 0.7),
                      MakeConstituent("tabulated", tabulated, Spectrum(1e-5), Spectrum(0.0), PhaseKind::kIsotropic),
                      MakeConstituent("vacuum", Constant(0.0), Spectrum(1e-5), Spectrum(0.0), PhaseKind::kIsotropic)};
    extremes.push_back(a);
  }
  {
    Atmosphere a = Planet("giant", 70000e3, 70000e3 + 1000e3);
    a.constituents = {Rayleigh(27000.0), MakeConstituent("haze", Exponential(5.0), Spectrum(1e-5), Spectrum(0.0),
                                                         PhaseKind::kHenyeyGreenstein, 0.9)};
    extremes.push_back(a);
  }
  for (const Atmosphere& atmosphere : extremes) {
    FitSet set;
    ASSERT_NO_THROW(set = FitAtmosphere(atmosphere, {}, FitOptions{})) << atmosphere.name;
    ExpectAllFinite(atmosphere, set);
  }
  // The vacuum constituent has nothing to fit; the others do.
  FitSet gaps = FitAtmosphere(extremes[2], {}, FitOptions{});
  EXPECT_FALSE(gaps.constituents[3].fitted);
  EXPECT_TRUE(gaps.constituents[1].fitted);
  EXPECT_TRUE(gaps.constituents[2].fitted);

  // Observers above the atmosphere, and a single observer altitude.
  FitOptions above;
  above.altitude_min_m = 100e3;
  above.altitude_max_m = 200e3;
  FitSet none = FitAtmosphere(Earth(), {}, above);
  for (const ConstituentFit& c : none.constituents) EXPECT_FALSE(c.fitted);
  ExpectAllFinite(Earth(), none);
  FitOptions one;
  one.altitude_min_m = one.altitude_max_m = 500.0;
  FitSet single = FitAtmosphere(Earth(), {}, one);
  ExpectAllFinite(Earth(), single);
  EXPECT_TRUE(single.constituents[0].fitted);
  EXPECT_LT(single.constituents[0].validation_errors.max_relative, 0.01);
}

TEST(Fit, ZeroConstituentsIsAnEmptyFitSetNotAnError) {
  Atmosphere empty = Planet("empty", kEarthRadius, kEarthTop);
  FitSet set = FitAtmosphere(empty, {}, FitOptions{});
  EXPECT_TRUE(set.constituents.empty());
  EXPECT_EQ(set.air, -1);
}

TEST(Fit, RejectsUnknownConstituentsAndBadRanges) {
  EXPECT_THROW(FitAtmosphere(Earth(), {"nitrogen"}, FitOptions{}), InputError);
  FitOptions reversed;
  reversed.altitude_min_m = 2000.0;
  reversed.altitude_max_m = 1000.0;
  EXPECT_THROW(FitAtmosphere(Earth(), {}, reversed), InputError);
  FitOptions negative;
  negative.altitude_min_m = -1.0;
  EXPECT_THROW(FitAtmosphere(Earth(), {}, negative), InputError);
  FitSet only = FitAtmosphere(Earth(), {"mie"}, FitOptions{});
  ASSERT_EQ(only.constituents.size(), 1u);
  EXPECT_EQ(only.constituents[0].name, "mie");
  EXPECT_EQ(only.air, -1);  // no Rayleigh constituent selected
  EXPECT_EQ(only.haze, 0);
}

TEST(Fit, SolverRefusesNonFiniteData) {
  // A failed solve must surface as unusable (FitConstituent then throws
  // InternalError, exit code 4), never as NaN coefficients.
  FitSamples samples;
  samples.mu = {1.0, 0.5, 0.0};
  samples.t = {0.0, 0.0, 0.0};
  samples.ln_target = {0.0, std::nan(""), 3.0};
  std::array<double, kCoefficientCount> guess{};
  guess.fill(-1.0);
  SolverResult result = SolveForm(FormKind::kChapmanChord, samples, {guess}, true);
  EXPECT_FALSE(result.usable);
}

TEST(Fit, IdentifiersAreSafeAndUnique) {
  EXPECT_EQ(MakeIdentifier("Rayleigh", {}), "rayleigh");
  EXPECT_EQ(MakeIdentifier("CO2 dust (fine)", {}), "co2_dust_fine");
  EXPECT_EQ(MakeIdentifier("2nd", {}), "c2nd");
  EXPECT_EQ(MakeIdentifier("__", {}), "c");
  EXPECT_EQ(MakeIdentifier("a--b", {}), "a_b");  // GLSL reserves "__"
  EXPECT_EQ(MakeIdentifier("mie", {"mie"}), "mie_2");
}

}  // namespace
}  // namespace skybake::fit
