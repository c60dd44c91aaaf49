// Validation of the reference solver's building blocks (reference/): its
// sampling routines and its deterministic integrals (quadrature, optical
// depths, free flights). Tolerances: see reference_test_util.h.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "reference/direction_guide.h"
#include "reference/layered_medium.h"
#include "reference/phase_sampling.h"
#include "reference/quadrature.h"
#include "reference/random.h"
#include "reference/ray_segment.h"
#include "reference/sunlight_table.h"
#include "shaders_runtime/runtime.h"
#include "reference_test_util.h"

namespace skybake::reference {
namespace {

using glm::dvec3;

// ---------------------------------------------------------------------------
// Sampling routines.

// Probability that the cosine of a sample from `phase` falls in [a, b]:
// 2 pi times the integral of the phase, by composite Simpson.
double PhaseProbability(const PhaseFunction& phase, double a, double b, int n = 200) {
  double h = (b - a) / n, sum = phase.Evaluate(a) + phase.Evaluate(b);
  for (int i = 1; i < n; ++i) sum += phase.Evaluate(a + i * h) * (i % 2 ? 4.0 : 2.0);
  return 2.0 * kPi * sum * h / 3.0;
}

struct PhaseCase {
  const char* name;
  PhaseFunction phase;
};

TEST(ReferenceSampling, PhaseSamplesFollowThePhaseFunction) {
  // Chi-square over 40 equal bins in cos(theta) of 400k samples. The least
  // likely bin (backward, HG g = 0.8) expects ~600 samples, so the statistic
  // follows chi-square with 39 degrees of freedom: its 0.999 quantile is
  // 72.1. A sampler using HG's misprinted (1 - g)^2 numerator, or sampling CS
  // as plain HG, scores in the thousands.
  const PhaseCase cases[] = {{"Rayleigh", {PhaseKind::kRayleigh, 0.0}},
                             {"HG 0.8", {PhaseKind::kHenyeyGreenstein, 0.8}},
                             {"CS 0.8", {PhaseKind::kCornetteShanks, 0.8}},
                             {"HG -0.5", {PhaseKind::kHenyeyGreenstein, -0.5}},
                             {"isotropic", {PhaseKind::kIsotropic, 0.0}}};
  const int bins = 40, samples = 400000;
  for (const PhaseCase& c : cases) {
    Pcg32 rng(12345, 678);
    std::vector<int> counts(bins, 0);
    for (int i = 0; i < samples; ++i) {
      double mu = SamplePhaseCosine(c.phase, rng);
      ASSERT_GE(mu, -1.0);
      ASSERT_LE(mu, 1.0);
      counts[std::min(bins - 1, static_cast<int>((mu + 1.0) / 2.0 * bins))]++;
    }
    double chi2 = 0.0, total_probability = 0.0;
    for (int b = 0; b < bins; ++b) {
      double p = PhaseProbability(c.phase, -1.0 + 2.0 * b / bins, -1.0 + 2.0 * (b + 1) / bins);
      total_probability += p;
      double expected = p * samples;
      chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
    }
    EXPECT_NEAR(total_probability, 1.0, 1e-9) << c.name;
    Note("phase %s: chi2 %.1f (39 dof)\n", c.name, chi2);
    EXPECT_LT(chi2, 72.1) << c.name;
  }
}

TEST(ReferenceSampling, InverseCdfsRoundTrip) {
  // CDF(sample(u)) = u, with the CDF integrated from the phase function
  // (fine Simpson steps: the g = 0.8 lobe is ~0.02 wide in cos(theta)).
  PhaseFunction hg{PhaseKind::kHenyeyGreenstein, 0.8}, rayleigh{PhaseKind::kRayleigh, 0.0};
  for (double u = 0.01; u < 1.0; u += 0.07) {
    EXPECT_NEAR(PhaseProbability(hg, -1.0, SampleHenyeyGreensteinCosine(0.8, u), 20000), u, 1e-9) << u;
    EXPECT_NEAR(PhaseProbability(rayleigh, -1.0, SampleRayleighCosine(u)), u, 1e-9) << u;
  }
}

TEST(ReferenceSampling, CosineHemisphere) {
  // Mean of cos(theta) under the density cos / pi is 2/3; of cos^2, 1/2.
  dvec3 normal = glm::normalize(dvec3(0.3, -0.5, 0.8));
  Pcg32 rng(1, 1);
  double sum = 0.0, sum2 = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    double u1 = rng.Uniform(), u2 = rng.Uniform();
    double c = glm::dot(SampleCosineHemisphere(normal, u1, u2), normal);
    ASSERT_GE(c, 0.0);
    sum += c;
    sum2 += c * c;
  }
  // Standard deviations of cos: sqrt(1/2 - 4/9) = 0.236 -> 5e-4 on the mean.
  EXPECT_NEAR(sum / n, 2.0 / 3.0, 4 * 0.236 / std::sqrt(double(n)));
  EXPECT_NEAR(sum2 / n, 0.5, 4 * 0.25 / std::sqrt(double(n)));
}

// ---------------------------------------------------------------------------
// Deterministic integrals.

TEST(ReferenceQuadrature, GaussKronrodIsExactForPolynomials) {
  // Kronrod-15 integrates degree 22 exactly, Gauss-7 degree 13.
  auto poly = [](int degree) {
    return [degree](double t) { return Spectrum(std::pow(t, degree)); };
  };
  for (int degree : {0, 5, 13, 22}) {
    GaussKronrodResult r = GaussKronrod15(poly(degree), -0.5, 2.0);
    double exact = (std::pow(2.0, degree + 1) - std::pow(-0.5, degree + 1)) / (degree + 1);
    EXPECT_NEAR(r.kronrod.x, exact, 1e-12 * std::abs(exact)) << degree;
    if (degree <= 13) {
      EXPECT_NEAR(r.gauss.x, exact, 1e-12 * std::abs(exact)) << degree;
    }
  }
  GaussKronrodResult e = GaussKronrod15([](double t) { return Spectrum(std::exp(t)); }, 0.0, 1.0);
  EXPECT_NEAR(e.kronrod.x, std::exp(1.0) - 1.0, 1e-15);
}

TEST(ReferenceQuadrature, OpticalDepthMatchesClosedForms) {
  Atmosphere a = Earth();
  a.constituents.resize(1);  // Rayleigh only: exp(-h / H)
  LayeredMedium medium(a);
  const double H = 8000.0, sigma = 33.1e-6;
  // Straight up from altitude h0 to the top: sigma H (e^-h0/H - e^-60km/H).
  for (double h0 : {0.0, 1500.0, 30000.0}) {
    double r = a.bottom_radius_m + h0;
    OpticalDepthEstimate tau = medium.OpticalDepth(r, 1.0, 0.0, a.top_radius_m - r, 1e-12);
    double exact = sigma * H * (std::exp(-h0 / H) - std::exp(-60000.0 / H));
    EXPECT_NEAR(tau.value.z, exact, 1e-12 * exact) << h0;
    EXPECT_LT(tau.error.z, 1e-9 * exact);
  }
  // A constant layer crossed on a grazing chord: sigma x length.
  Atmosphere slab = Earth();
  slab.constituents.resize(1);
  slab.constituents[0].density.layers = {DensityLayer{20000.0, 0.0, 0.0, 0.0, 1.0},
                                         DensityLayer{0.0, 0.0, 0.0, 0.0, 0.0}};
  LayeredMedium slab_medium(slab);
  double r = slab.bottom_radius_m + 5000.0, mu = -0.02;
  double length = glsl::DistanceToTopAtmosphereBoundary(slab_medium.geometry(), r, mu);
  // The chord inside the 20 km layer, from the ray's own sphere crossings.
  double b = r * mu, c = r * r - std::pow(slab.bottom_radius_m + 20000.0, 2);
  double inside = -b + std::sqrt(b * b - c);
  OpticalDepthEstimate tau = slab_medium.OpticalDepth(r, mu, 0.0, length, 1e-12);
  EXPECT_NEAR(tau.value.z, sigma * inside, 1e-9 * sigma * inside);
}

TEST(ReferenceMedium, MajorantsBoundTheExtinction) {
  // Earth, plus a layer whose formula peaks inside a shell (exp + linear)
  // and a tabulated profile.
  Atmosphere a = Earth();
  Constituent bump;
  bump.name = "bump";
  bump.density.layers = {DensityLayer{0.0, -1.0, -1.0 / 3000.0, 1.0 / 20000.0, 0.5}};
  bump.scattering_per_m = Spectrum(2e-6);
  a.constituents.push_back(bump);
  Constituent table;
  table.name = "table";
  table.density.kind = DensityProfile::Kind::kTabulated;
  table.density.altitudes_m = {0.0, 3000.0, 3500.0, 12000.0};
  table.density.densities = {0.2, 1.0, 0.1, 0.0};
  table.scattering_per_m = Spectrum(5e-6);
  a.constituents.push_back(table);
  LayeredMedium medium(a);
  Pcg32 rng(3, 4);
  for (int i = 0; i < 200000; ++i) {
    double r = a.bottom_radius_m + (a.top_radius_m - a.bottom_radius_m) * rng.Uniform();
    Spectrum extinction = medium.Extinction(r);
    int s = medium.ShellIndex(r);
    for (int w = 0; w < kWavelengthCount; ++w) ASSERT_LE(extinction[w], medium.Majorant(s, w)) << r;
  }
}

TEST(ReferenceMedium, FreeFlightsEscapeWithTheTransmittance) {
  // Delta tracking: the fraction of free flights that cross a ray without a
  // collision is T = exp(-tau); binomial sigma = sqrt(T (1 - T) / n).
  LayeredMedium medium(Earth());
  const glsl::AtmosphereParameters& g = medium.geometry();
  const int n = 100000;
  struct Ray {
    double altitude, mu;
    int w;
  };
  for (Ray ray : {Ray{0.0, 1.0, 2}, Ray{0.0, 0.02, 2}, Ray{0.0, 0.02, 0}, Ray{8000.0, -0.1, 1}}) {
    double r = g.bottom_radius + ray.altitude;
    bool ground = glsl::RayIntersectsGround(g, r, ray.mu);
    double length = ground ? glsl::DistanceToBottomAtmosphereBoundary(g, r, ray.mu)
                           : glsl::DistanceToTopAtmosphereBoundary(g, r, ray.mu);
    double transmittance = std::exp(-medium.OpticalDepth(r, ray.mu, 0.0, length, 1e-10).value[ray.w]);
    Pcg32 rng(99, 7);
    int crossed = 0;
    for (int i = 0; i < n; ++i) {
      RayEvent e = medium.SampleFreeFlight(r, ray.mu, std::numeric_limits<double>::infinity(), ray.w, rng);
      if (e.end != RayEnd::kCollision) {
        ++crossed;
        EXPECT_EQ(e.end, ground ? RayEnd::kGround : RayEnd::kSpace);
        EXPECT_NEAR(e.distance, length, 1e-6 * length);
      }
    }
    double sigma = std::sqrt(transmittance * (1.0 - transmittance) / n);
    EXPECT_NEAR(double(crossed) / n, transmittance, 4.0 * sigma) << ray.altitude << " " << ray.mu;
  }
}

TEST(ReferenceMedium, RatioTrackingIsUnbiased) {
  LayeredMedium medium(Earth());
  const glsl::AtmosphereParameters& g = medium.geometry();
  double r = g.bottom_radius + 500.0, mu = 0.05;
  double length = glsl::DistanceToTopAtmosphereBoundary(g, r, mu);
  Pcg32 rng(5, 6);
  for (int w = 0; w < kWavelengthCount; ++w) {
    double exact = std::exp(-medium.OpticalDepth(r, mu, 0.0, length, 1e-10).value[w]);
    const int n = 50000;
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
      double t = medium.RatioTrackingTransmittance(r, mu, length, w, rng);
      sum += t;
      sum2 += t * t;
    }
    double mean = sum / n, sigma = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, exact, 4.0 * sigma + 1e-12) << w;
  }
}

TEST(ReferenceSampling, GuidedDistancesAreUnbiased) {
  // The mean of sigma_t(t) T(t) / pdf(t) over the segment is the integral of
  // sigma_t T, 1 - T(segment), whatever the guide: a spike on one piece,
  // pieces without weight, the sunlight at sunset. Stratified u: the
  // estimate's error is that of the strata, tested at 1e-3 (2e-2 in
  // relative terms of the guided part would already show a wrong factor).
  LayeredMedium medium(Earth());
  const SunlightTable sunlight(medium);
  const dvec3 camera(0.0, 0.0, medium.bottom_radius() + 200.0);
  const dvec3 sun(std::sin(96.0 * kDegree), 0.0, std::cos(96.0 * kDegree));
  for (const RaySegment::Table table : {RaySegment::Table::kExact, RaySegment::Table::kSampling}) {
    for (double view_zenith : {0.0, 80.0, 89.0}) {
      const dvec3 view(std::sin(view_zenith * kDegree), 0.0, std::cos(view_zenith * kDegree));
      const RaySegment segment(medium, camera, view, 0.0, table);
      Spectrum error;
      const Spectrum expected = Spectrum(1.0) - RaySegment(medium, camera, view, 0.0, RaySegment::Table::kExact)
                                                    .Transmittance(&error);
      const std::vector<double> middles = segment.PieceMiddles();
      for (int w = 0; w < kWavelengthCount; ++w) {
        std::vector<double> spike(middles.size(), 0.0), sunset;
        spike[middles.size() / 2] = 1.0;
        for (double t : middles) {
          const dvec3 x = segment.origin() + t * view;
          sunset.push_back(sunlight.At(glm::length(x), glm::dot(x, sun) / glm::length(x))[w]);
        }
        for (const std::vector<double>& weights : {spike, sunset}) {
          const RaySegment::Mixture mixture = segment.MakeMixture(w, weights, 0.5);
          const int n = 20000;
          double sum = 0.0;
          for (int i = 0; i < n; ++i) {
            double t, transmittance_over_pdf;
            ASSERT_TRUE(segment.SampleMixture(medium, mixture, (i + 0.5) / n, &t, &transmittance_over_pdf));
            ASSERT_GE(t, 0.0);
            ASSERT_LE(t, segment.length());
            sum += medium.Extinction(glm::length(segment.origin() + t * view), w) * transmittance_over_pdf;
          }
          EXPECT_NEAR(sum / n, expected[w], 1e-3 * expected[w]) << "view " << view_zenith << " w " << w;
        }
      }
    }
  }
}

TEST(ReferenceSampling, DirectionGuideSamplesItsOwnDensity) {
  // Sample and Pdf describe the same density: Pdf integrates to 1 over the
  // sphere (on a grid 8 times finer than its azimuth cells and spaced
  // about half its thinnest zenith cells, next to the horizon), and the fraction
  // of 200 000 samples in each of 8 x 8 regions (in the world's cos z and
  // azimuth, not the guide's own frame) matches the integral of Pdf there
  // within 4.5 binomial standard deviations plus 2e-4 (the grid's edges).
  // After sunset, from the ground and from 20 km: each wavelength's guide,
  // and the mixtures of the field around those points.
  LayeredMedium medium(Earth());
  const SunlightTable sunlight(medium);
  const dvec3 sun(std::sin(98.0 * kDegree), 0.0, std::cos(98.0 * kDegree));
  constexpr int kRegions = 8, kFineZenith = 8192, kFineAzimuth = 256;
  auto region = [](const dvec3& d) {
    const int i = std::clamp(static_cast<int>((d.z + 1.0) * 0.5 * kRegions), 0, kRegions - 1);
    double phi = std::atan2(d.y, d.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    return i * kRegions + std::clamp(static_cast<int>(phi / (2.0 * kPi) * kRegions), 0, kRegions - 1);
  };
  // Sample(u_guide, u_cell, u1, u2) and Pdf of a guide or a mixture of them.
  auto check = [&](auto sample, auto pdf, const std::string& label) {
    std::vector<double> expected(kRegions * kRegions, 0.0), observed(kRegions * kRegions, 0.0);
    double total = 0.0;
    const double cell = (2.0 / kFineZenith) * (2.0 * kPi / kFineAzimuth);
    for (int i = 0; i < kFineZenith; ++i) {
      const double c = -1.0 + 2.0 * (i + 0.5) / kFineZenith, s = std::sqrt(1.0 - c * c);
      for (int j = 0; j < kFineAzimuth; ++j) {
        const double phi = 2.0 * kPi * (j + 0.5) / kFineAzimuth;
        const dvec3 d(s * std::cos(phi), s * std::sin(phi), c);
        const double p = pdf(d) * cell;
        total += p;
        expected[region(d)] += p;
      }
    }
    EXPECT_NEAR(total, 1.0, 1e-3) << label;
    Pcg32 rng(7, 8);
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
      const double u_guide = rng.Uniform(), u = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
      const dvec3 d = sample(u_guide, u, u1, u2);
      ASSERT_NEAR(glm::length(d), 1.0, 1e-12) << label;
      ASSERT_GT(pdf(d), 0.0) << label;
      observed[region(d)] += 1.0 / n;
    }
    for (int r = 0; r < kRegions * kRegions; ++r) {
      const double sigma = std::sqrt(expected[r] * (1.0 - expected[r]) / n);
      EXPECT_NEAR(observed[r], expected[r], 4.5 * sigma + 2e-4) << label << " region " << r;
    }
  };
  for (double altitude : {0.0, 20000.0}) {
    const dvec3 point(0.0, 0.0, medium.bottom_radius() + altitude);
    const GuideFrame frame(point, sun);
    const double r = glm::length(point), mu_s = glm::dot(point, sun) / r;
    for (int w = 0; w < kWavelengthCount; ++w) {
      const DirectionGuide guide(medium, sunlight, nullptr, r, mu_s, w);
      ASSERT_TRUE(guide.usable());
      check([&](double, double u, double u1, double u2) { return guide.Sample(frame, u, u1, u2); },
            [&](const dvec3& d) { return guide.Pdf(frame, d); },
            "guide at " + std::to_string(altitude) + " m, wavelength " + std::to_string(w));
    }
    // The field's mixture of four guides around the point (its altitude and
    // sun cosine lie between the field's nodes), single and double scattering.
    const DirectionGuideField single(medium, sunlight, nullptr, 0);
    const DirectionGuideField twice(medium, sunlight, &single, 0);
    for (const DirectionGuideField* field : {&single, &twice}) {
      const GuideMixture mixture = field->At(r + 1500.0, mu_s);
      ASSERT_TRUE(mixture.usable());
      check([&](double ug, double u, double u1, double u2) { return mixture.Sample(frame, ug, u, u1, u2); },
            [&](const dvec3& d) { return mixture.Pdf(frame, d); },
            std::string(field == &single ? "single" : "double") + " scattering mixture at " +
                std::to_string(altitude) + " m");
    }
  }
}

}  // namespace
}  // namespace skybake::reference
