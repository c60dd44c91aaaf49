// The scattering density's phase on the rings of its sphere rule
// (bake/ring_phase.h): the azimuthal Fourier coefficients of each phase
// against the plain midpoint rule on many times the nodes, the cosine series
// through a ring's samples, and the whole mean against a sum over a fine
// azimuth grid of the same series.
#include "bake/ring_phase.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/constants.h"

namespace skybake::detail {
namespace {

// c_k by the plain midpoint rule on `nodes` nodes over [0, pi]: spectrally
// accurate for a periodic analytic integrand once the nodes resolve its
// narrowest peak (g = 0.999: about 1e-3 rad wide, 2^17 nodes put 40 across
// it) and its highest term.
std::vector<double> BruteForceCoefficients(const PhaseFunction& phase, double view_mu, double ring_cos, int terms,
                                           int nodes) {
  const double a = view_mu * ring_cos;
  const double b = std::sqrt(1.0 - view_mu * view_mu) * std::sqrt(1.0 - ring_cos * ring_cos);
  std::vector<double> c(terms, 0.0);
  for (int q = 0; q < nodes; ++q) {
    const double psi = (q + 0.5) * kPi / nodes;
    const double cos_psi = std::cos(psi);
    const double value = phase.Evaluate(std::clamp(a + b * cos_psi, -1.0, 1.0));
    double previous = 1.0, current = cos_psi;  // cos((k - 1) psi), cos(k psi)
    c[0] += value;
    for (int k = 1; k < terms; ++k) {
      c[k] += value * current;
      const double next = 2.0 * cos_psi * current - previous;
      previous = current, current = next;
    }
  }
  for (double& ck : c) ck *= 2.0 * kPi / nodes;
  return c;
}

const std::vector<PhaseFunction> kPhases = {
    {PhaseKind::kIsotropic, 0.0},         {PhaseKind::kRayleigh, 0.0},           {PhaseKind::kCornetteShanks, 0.8},
    {PhaseKind::kHenyeyGreenstein, 0.85}, {PhaseKind::kHenyeyGreenstein, 0.999}, {PhaseKind::kHenyeyGreenstein, -0.999},
    {PhaseKind::kCornetteShanks, -0.5},
};
const std::vector<double> kCosines = {-0.9, -0.3, 0.0, 0.02, 0.5, 0.97, 0.9995};

TEST(RingPhase, AzimuthCoefficientsMatchAFineMidpointRule) {
  // 16 terms: the default sphere rule's; 64: --sphere-samples 64, where the
  // lobe's rule needs more nodes for cos(k psi).
  for (int terms : {16, 64})
    for (const PhaseFunction& phase : kPhases) {
      const PhaseAzimuthSeries series(phase, terms);
      double worst = 0.0;
      for (double view_mu : kCosines) {
        for (double ring_cos : kCosines) {
          std::vector<double> c(terms);
          series.Coefficients(view_mu, ring_cos, c.data());
          const std::vector<double> exact = BruteForceCoefficients(phase, view_mu, ring_cos, terms, 1 << 17);
          ASSERT_GT(exact[0], 0.0);
          for (int k = 0; k < terms; ++k) worst = std::max(worst, std::abs(c[k] - exact[k]) / exact[0]);
        }
      }
      // Relative to c_0 (the ring's weight in the mean): far below the float
      // the coefficients are stored in.
      EXPECT_LT(worst, 1e-7) << ToString(phase.kind) << " g = " << phase.g << ", " << terms << " terms";
    }
}

TEST(RingPhase, CosineSeriesPassesThroughTheSamples) {
  const int samples = 16;
  const AzimuthCosineSeries series(samples);
  std::vector<double> values(samples);
  for (int m = 0; m < samples; ++m) values[m] = std::exp(-3.0 * m / samples) + (m == 2 ? 5.0 : 0.0);
  std::vector<float> a(samples);
  series.Coefficients(values.data(), a.data());
  std::vector<double> cos_phi(samples), multiples(samples * samples);
  for (int m = 0; m < samples; ++m) cos_phi[m] = std::cos((m + 0.5) * kPi / samples);
  CosineMultiples(cos_phi.data(), samples, samples, multiples.data());
  for (int m = 0; m < samples; ++m) {
    double sum = 0.0;
    for (int k = 0; k < samples; ++k) {
      EXPECT_NEAR(multiples[k * samples + m], std::cos(k * (m + 0.5) * kPi / samples), 1e-12);
      sum += a[k] * multiples[k * samples + m];
    }
    EXPECT_NEAR(sum, values[m], 1e-5 * 6.0) << "m = " << m;
  }
}

// The mean over two rings of a radiance given as a cosine series, against
// the same phase-weighted mean summed over 2^16 azimuths per ring (about 50
// across the narrowest lobe, g = 0.999).
TEST(RingPhase, MeanMatchesAFineAzimuthSum) {
  const int terms = 16;
  const std::vector<double> ring_cos = {0.1, 0.6}, ring_weights = {0.7, 0.3};
  const std::vector<double> view_mu = {0.3};
  // Per ring, its series: a smooth radiance rising toward the sun (phi = 0),
  // the same in the three channels.
  const int stride = RingPhaseMeans::kTermBlock;
  std::vector<float> a(3 * 2 * stride, 0.0f);
  for (int c = 0; c < 3; ++c) {
    for (int l = 0; l < 2; ++l) {
      for (int k = 0; k < terms; ++k) a[(c * 2 + l) * stride + k] = float((l + 1) * std::pow(0.6, k));
    }
  }
  for (const PhaseFunction& phase : kPhases) {
    const RingPhaseMeans means({PhaseAzimuthSeries(phase, terms)}, {Spectrum(1.0)}, view_mu, ring_cos, ring_weights,
                               terms);
    ASSERT_EQ(means.Stride(), stride);
    std::vector<float> view_terms(3 * stride);
    means.Terms(0, a.data(), view_terms.data());
    for (double phi_v : {0.0, 0.4, 2.0, kPi}) {
      const double cos_phi_v = std::cos(phi_v);
      std::vector<double> multiples(terms);
      CosineMultiples(&cos_phi_v, 1, terms, multiples.data());
      double mean = 0.0;
      for (int k = 0; k < terms; ++k) mean += view_terms[k] * multiples[k];
      const int n = 1 << 16;
      double sum = 0.0, weight = 0.0;
      const double view_sin = std::sqrt(1.0 - view_mu[0] * view_mu[0]);
      for (int l = 0; l < 2; ++l) {
        const double ring_sin = std::sqrt(1.0 - ring_cos[l] * ring_cos[l]);
        for (int m = 0; m < n; ++m) {
          const double phi = (m + 0.5) * 2.0 * kPi / n;
          double radiance = 0.0, previous = 1.0, current = std::cos(phi);
          for (int k = 0; k < terms; ++k) {
            radiance += double(a[l * stride + k]) * (k == 0 ? 1.0 : current);
            if (k > 0) {
              const double next = 2.0 * std::cos(phi) * current - previous;
              previous = current, current = next;
            }
          }
          const double w =
              ring_weights[l] * phase.Evaluate(view_mu[0] * ring_cos[l] + view_sin * ring_sin * std::cos(phi - phi_v));
          sum += w * radiance;
          weight += w;
        }
      }
      EXPECT_NEAR(mean, sum / weight, 1e-5 * std::abs(sum / weight))
          << ToString(phase.kind) << " g = " << phase.g << " phi_v = " << phi_v;
    }
  }
}

// Two groups' weights, folded with their shares per channel, give the
// shares' blend of each group's own mean.
TEST(RingPhase, GroupsWeighedByTheirSharesPerChannel) {
  const int terms = 16, stride = RingPhaseMeans::kTermBlock;
  const std::vector<double> ring_cos = {-0.4, 0.05, 0.7}, ring_weights = {0.5, 0.2, 0.3}, view_mu = {0.1, 0.8};
  const PhaseAzimuthSeries rayleigh({PhaseKind::kRayleigh, 0.0}, terms);
  const PhaseAzimuthSeries haze({PhaseKind::kCornetteShanks, 0.8}, terms);
  const Spectrum air_share(0.9, 0.6, 0.2);
  const RingPhaseMeans both({rayleigh, haze}, {air_share, Spectrum(1.0) - air_share}, view_mu, ring_cos, ring_weights,
                            terms);
  const RingPhaseMeans air({rayleigh}, {Spectrum(1.0)}, view_mu, ring_cos, ring_weights, terms);
  const RingPhaseMeans haze_only({haze}, {Spectrum(1.0)}, view_mu, ring_cos, ring_weights, terms);
  std::vector<float> a(3 * 3 * stride, 0.0f);
  for (int i = 0; i < int(a.size()); ++i) a[i] = (i % stride) < terms ? float(1.0 + 0.3 * std::sin(i)) : 0.0f;
  for (int view = 0; view < 2; ++view) {
    std::vector<float> out(3 * stride), out_air(3 * stride), out_haze(3 * stride);
    both.Terms(view, a.data(), out.data());
    air.Terms(view, a.data(), out_air.data());
    haze_only.Terms(view, a.data(), out_haze.data());
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < terms; ++k) {
        const double blend = air_share[c] * out_air[c * stride + k] + (1.0 - air_share[c]) * out_haze[c * stride + k];
        EXPECT_NEAR(out[c * stride + k], blend, 1e-6) << "view " << view << " channel " << c << " k " << k;
      }
    }
  }
}

// A view's weights do not depend on the other views they are computed with:
// the scattering density computes them per view where it does not keep
// them for a whole row.
TEST(RingPhase, OneViewsWeightsAloneAsAmongOthers) {
  const int terms = 16, stride = RingPhaseMeans::kTermBlock;
  const std::vector<double> ring_cos = {-0.5, 0.0, 0.4, 0.95}, ring_weights = {0.4, 0.1, 0.3, 0.2};
  const std::vector<PhaseAzimuthSeries> series = {PhaseAzimuthSeries({PhaseKind::kRayleigh, 0.0}, terms),
                                                  PhaseAzimuthSeries({PhaseKind::kHenyeyGreenstein, 0.85}, terms)};
  const std::vector<Spectrum> shares = {Spectrum(0.3, 0.5, 0.8), Spectrum(0.7, 0.5, 0.2)};
  const std::vector<double> views = {-0.7, 0.05, 0.6};
  const RingPhaseMeans all(series, shares, views, ring_cos, ring_weights, terms);
  std::vector<float> a(3 * 4 * stride, 0.0f);
  for (int i = 0; i < int(a.size()); ++i) a[i] = (i % stride) < terms ? float(std::cos(0.7 * i)) : 0.0f;
  for (int view = 0; view < 3; ++view) {
    const RingPhaseMeans alone(series, shares, {views[view]}, ring_cos, ring_weights, terms);
    std::vector<float> among(3 * stride), single(3 * stride);
    all.Terms(view, a.data(), among.data());
    alone.Terms(0, a.data(), single.data());
    EXPECT_EQ(among, single) << "view " << view;
  }
}

}  // namespace
}  // namespace skybake::detail
