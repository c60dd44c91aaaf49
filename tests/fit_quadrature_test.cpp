// Tests of the fit's integrals: the adaptive Gauss-Kronrod quadrature against
// closed forms, and the exact vertical and slant columns and relative optical
// path against closed forms, the Chapman asymptote and brute force.
#include <cmath>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "core/errors.h"
#include "fit/optical_path.h"
#include "fit/quadrature.h"
#include "fit_test_util.h"

namespace skybake::fit {
namespace {

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

}  // namespace
}  // namespace skybake::fit
