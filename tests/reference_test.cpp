// Validation of the independent reference solver (reference/): sampling
// routines and quadrature rules. Sampling checks use fixed seeds, so they
// are deterministic; SKYBAKE_REFERENCE_TEST_VERBOSE=1 prints the measured
// figures.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "bake/atmosphere.h"
#include "reference/phase_sampling.h"
#include "reference/quadrature.h"
#include "reference/random.h"

namespace skybake::reference {
namespace {

using glm::dvec3;
constexpr double kPi = 3.14159265358979323846;

void Note(const char* format, ...) {
  if (!std::getenv("SKYBAKE_REFERENCE_TEST_VERBOSE")) return;
  va_list args;
  va_start(args, format);
  std::vprintf(format, args);
  va_end(args);
}

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

}  // namespace
}  // namespace skybake::reference
