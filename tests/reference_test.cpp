// Validation of the independent reference solver (reference/): its sampling
// routines, its deterministic integrals, and its Monte Carlo estimates
// against an independent quadrature and a conservation law.
//
// Monte Carlo tolerances are stated in standard errors (sigma). Seeds are
// fixed, so every test is deterministic; the tolerances are set so that a
// correct solver passes for the vast majority of seeds (4 sigma: 6e-5 two-sided
// for a Gaussian), while the errors they guard against (a missing factor,
// a wrong phase normalisation, a biased sampler) move the estimate by tens
// or hundreds of sigma. SKYBAKE_REFERENCE_TEST_SCALE=k multiplies the path
// counts by k, to rerun the same checks at higher precision;
// SKYBAKE_REFERENCE_TEST_VERBOSE=1 prints the measured figures.
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "core/errors.h"
#include "reference/layered_medium.h"
#include "reference/path_tracer.h"
#include "reference/phase_sampling.h"
#include "reference/quadrature.h"
#include "reference/query_csv.h"
#include "reference/random.h"
#include "shaders_runtime/runtime.h"

namespace skybake::reference {
namespace {

using glm::dvec3;
constexpr double kDegree = kPi / 180.0;

int64_t Scaled(int64_t paths) {
  const char* scale = std::getenv("SKYBAKE_REFERENCE_TEST_SCALE");
  return scale ? paths * std::max(1, std::atoi(scale)) : paths;
}

void Note(const char* format, ...) {
  if (!std::getenv("SKYBAKE_REFERENCE_TEST_VERBOSE")) return;
  va_list args;
  va_start(args, format);
  std::vprintf(format, args);
  va_end(args);
}

// Earth, with the parameter values of DESIGN.md (Bruneton's 2017 set).
Atmosphere Earth() {
  Atmosphere a;
  a.name = "earth";
  a.bottom_radius_m = 6360e3;
  a.top_radius_m = 6420e3;
  a.ground_albedo = Spectrum(0.1);
  a.solar_irradiance = Spectrum(1.474, 1.8504, 1.91198);
  a.sun_angular_radius_rad = 0.004675;
  a.mu_s_min = std::cos(102.0 * kDegree);
  Constituent rayleigh;
  rayleigh.name = "rayleigh";
  rayleigh.density.layers = {DensityLayer{0.0, 1.0, -1.0 / 8000.0, 0.0, 0.0}};
  rayleigh.scattering_per_m = Spectrum(5.802e-6, 13.558e-6, 33.1e-6);
  rayleigh.phase = {PhaseKind::kRayleigh, 0.0};
  Constituent mie;
  mie.name = "mie";
  mie.density.layers = {DensityLayer{0.0, 1.0, -1.0 / 1200.0, 0.0, 0.0}};
  mie.scattering_per_m = Spectrum(3.996e-6);
  mie.absorption_per_m = Spectrum(0.444e-6);
  mie.phase = {PhaseKind::kCornetteShanks, 0.8};
  Constituent ozone;
  ozone.name = "ozone";
  ozone.density.layers = {DensityLayer{25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0},
                          DensityLayer{0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0}};
  ozone.absorption_per_m = Spectrum(0.650e-6, 1.881e-6, 0.085e-6);
  a.constituents = {rayleigh, mie, ozone};
  return a;
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

// ---------------------------------------------------------------------------
// Monte Carlo estimates.

// An independent single-scattering integrator: plain composite Gauss-Legendre
// on uniform panels, extinction from DensityProfile::At, no shells, no
// tables, nothing from reference/ but the query geometry.

constexpr double kGauss4Nodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                    0.8611363115940526};
constexpr double kGauss4Weights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                      0.3478548451374538};

Spectrum BruteExtinction(const Atmosphere& a, const dvec3& x) {
  double h = glm::length(x) - a.bottom_radius_m;
  Spectrum sum(0.0);
  for (const Constituent& c : a.constituents) sum += c.Extinction() * c.density.At(h);
  return sum;
}

Spectrum BruteOpticalDepth(const Atmosphere& a, const dvec3& start, const dvec3& direction, double length,
                           int panels) {
  Spectrum tau(0.0);
  double h = length / panels;
  for (int p = 0; p < panels; ++p) {
    double centre = (p + 0.5) * h;
    for (int k = 0; k < 4; ++k) {
      tau += BruteExtinction(a, start + (centre + 0.5 * h * kGauss4Nodes[k]) * direction) *
             (0.5 * h * kGauss4Weights[k]);
    }
  }
  return tau;
}

// Distance to the sphere of `radius` along a ray from inside it.
double ExitDistance(const dvec3& x, const dvec3& d, double radius) {
  double b = glm::dot(x, d), c = glm::dot(x, x) - radius * radius;
  return -b + std::sqrt(std::max(0.0, b * b - c));
}

// Single-scattered radiance at the camera along the view ray up to the top,
// the ground, or `distance`: integral of T(camera, x) sum_c sigma_s,c(x)
// P_c(nu) E_sun V(x) T(x, sun) dx, each transmittance by its own quadrature.
Spectrum BruteSingleScattering(const Atmosphere& a, const RayQuery& q, int panels) {
  glsl::AtmosphereParameters g;
  g.bottom_radius = a.bottom_radius_m;
  g.top_radius = a.top_radius_m;
  g.sun_angular_radius = a.sun_angular_radius_rad;
  dvec3 camera = q.camera, view = glm::normalize(q.view), sun = glm::normalize(q.sun);
  double r = glm::length(camera);
  if (r > a.top_radius_m) {  // move a camera in space to where the ray enters
    double b = glm::dot(camera, view), c = r * r - a.top_radius_m * a.top_radius_m;
    camera += (-b - std::sqrt(b * b - c)) * view;
    r = a.top_radius_m;
  }
  double mu = glm::dot(camera, view) / r;
  double length = glsl::RayIntersectsGround(g, r, mu) ? glsl::DistanceToBottomAtmosphereBoundary(g, r, mu)
                                                      : ExitDistance(camera, view, a.top_radius_m);
  if (q.distance_m > 0.0) length = std::min(length, q.distance_m);
  const double nu = glm::dot(view, sun);
  Spectrum sum(0.0), tau(0.0);
  double h = length / panels;
  double previous_t = 0.0;
  for (int p = 0; p < panels; ++p) {
    double centre = (p + 0.5) * h;
    for (int k = 0; k < 4; ++k) {
      double t = centre + 0.5 * h * kGauss4Nodes[k];
      tau += BruteOpticalDepth(a, camera + previous_t * view, view, t - previous_t, 4);
      previous_t = t;
      dvec3 x = camera + t * view;
      double r_x = glm::length(x), mu_s = glm::dot(x, sun) / r_x;
      double visible = glsl::SunVisibleFraction(g, r_x, mu_s);
      if (visible <= 0.0) continue;
      // The convention of the model: a disc centre below the horizon is
      // seen (in part) along the horizon ray.
      dvec3 toward_sun = sun;
      if (glsl::RayIntersectsGround(g, r_x, mu_s)) {
        dvec3 zenith = x / r_x, tangent = glm::normalize(sun - mu_s * zenith);
        double mu_h = -std::sqrt(1.0 - std::pow(a.bottom_radius_m / r_x, 2));
        toward_sun = mu_h * zenith + std::sqrt(1.0 - mu_h * mu_h) * tangent;
      }
      Spectrum tau_sun = BruteOpticalDepth(a, x, toward_sun, ExitDistance(x, toward_sun, a.top_radius_m), 300);
      Spectrum scattered(0.0);
      for (const Constituent& c : a.constituents) {
        scattered += c.scattering_per_m * c.density.At(r_x - a.bottom_radius_m) * c.phase.Evaluate(nu);
      }
      sum += glm::exp(-tau - tau_sun) * scattered * a.solar_irradiance * visible * (0.5 * h * kGauss4Weights[k]);
    }
  }
  return sum;
}

RayQuery QueryAt(const Atmosphere& a, double altitude, double view_zenith, double sun_zenith, double azimuth,
                 double distance = 0.0) {
  Query q;
  q.altitude_m = altitude;
  q.view_zenith_deg = view_zenith;
  q.sun_zenith_deg = sun_zenith;
  q.view_sun_azimuth_deg = azimuth;
  q.distance_m = distance;
  return MakeRayQuery(q, a.bottom_radius_m);
}

TEST(ReferenceEstimates, SingleScatteringMatchesIndependentQuadrature) {
  // max_order = 1 on Earth against BruteSingleScattering. Only the first
  // vertex's distance is random (stratified), so the standard errors are
  // small (1e-4 to 2e-3 relative) and the check is sharp. Tolerance: 5 sigma
  // (27 comparisons, each a t statistic with 63 degrees of freedom: ~1e-4
  // chance of a false alarm in all) plus 2e-5 relative for the quadrature,
  // whose panels are converged to 2e-8 (measured by quadrupling them). Over
  // 100 seeds the deviations had mean -0.1 and rms 1.0 sigma.
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(4096);
  settings.max_order = 1;
  // Where the sun sets along the ray, the integrand has a steep edge that
  // 64 strata do not smooth out: those cases are noisier (up to 1%).
  struct Case {
    double altitude, view, sun, azimuth, distance, max_relative_sigma;
  };
  const Case cases[] = {
      {0.0, 0.0, 30.0, 0.0, 0.0, 2e-3},          // zenith, high sun
      {0.0, 85.0, 60.0, 180.0, 0.0, 2e-3},       // near the horizon, away from the sun
      {0.0, 89.5, 70.0, 10.0, 0.0, 2e-3},        // grazing, toward the sun (Mie peak)
      {5000.0, 100.0, 45.0, 0.0, 0.0, 2e-3},     // looking down onto the ground
      {0.0, 60.0, 30.0, 40.0, 20000.0, 2e-3},    // aerial perspective to a point
      {100000.0, 110.0, 30.0, 90.0, 0.0, 2e-3},  // from space, into the atmosphere
      {2000.0, 80.0, 88.0, 0.0, 0.0, 2e-3},      // low sun
      {2000.0, 80.0, 92.0, 0.0, 0.0, 2e-2},      // sun below the camera's horizon, lit further on
      {0.0, 85.0, 90.1, 0.0, 0.0, 2e-2},         // sun disc straddling the horizon
  };
  for (const Case& c : cases) {
    RayQuery q = QueryAt(a, c.altitude, c.view, c.sun, c.azimuth, c.distance);
    Result result = tracer.Evaluate(q, settings, 11);
    Spectrum expected = BruteSingleScattering(a, q, 400);
    for (int w = 0; w < kWavelengthCount; ++w) {
      double mc = result.radiance.mean[w], sigma = result.radiance.standard_error[w];
      Note("single: alt %g view %g sun %g az %g d %g w %d: mc %.7g quad %.7g rel.sigma %.2g dev %.2f sigma\n",
           c.altitude, c.view, c.sun, c.azimuth, c.distance, w, mc, expected[w], sigma / mc,
           (mc - expected[w]) / sigma);
      EXPECT_GT(sigma, 0.0);
      EXPECT_LT(sigma, c.max_relative_sigma * mc) << "the single-scattering estimate should be nearly noise free";
      EXPECT_NEAR(mc, expected[w], 5.0 * sigma + 2e-5 * expected[w])
          << "altitude " << c.altitude << " view " << c.view << " sun " << c.sun << " wavelength " << w
          << " (" << (mc - expected[w]) / sigma << " sigma)";
    }
  }
}

// A conservative atmosphere over a white ground on a planet so large that it
// is plane-parallel (radius 6.36e9 m: curvature effects ~ H / R ~ 1e-6):
// nothing is absorbed and nothing moves sideways on average, so everything
// the sun brings in leaves through the top. The upward irradiance at the top
// (sky irradiance for a normal pointing down, at the top: all orders of
// scattering and every ground reflection) must equal mu_s E_sun. This checks
// the multiple-scattering machinery as a whole: phase sampling and
// normalisation, the weights of free flights, forced collisions and ground
// bounces, next-event estimation, Russian roulette, the irradiance sampler.
TEST(ReferenceEstimates, WhiteGroundConservesEnergy) {
  Atmosphere a = Earth();
  a.name = "conservative";
  a.bottom_radius_m = 6360e6;
  a.top_radius_m = a.bottom_radius_m + 60e3;
  a.ground_albedo = Spectrum(1.0);
  a.constituents.resize(2);
  a.constituents[0].scattering_per_m *= 4.0;  // vertical optical depth 0.19, 0.43, 1.06
  a.constituents[1].scattering_per_m = Spectrum(4e-5);  // 0.048, no absorption
  a.constituents[1].absorption_per_m = Spectrum(0.0);
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(8192);
  for (double sun_zenith : {0.0, 60.0}) {
    RayQuery q;
    q.camera = dvec3(0.0, 0.0, a.top_radius_m);
    q.view = dvec3(0.0, 0.0, 1.0);
    q.sun = dvec3(std::sin(sun_zenith * kDegree), 0.0, std::cos(sun_zenith * kDegree));
    q.has_normal = true;
    q.normal = dvec3(0.0, 0.0, -1.0);
    Result result = tracer.Evaluate(q, settings, 3);
    EXPECT_EQ(result.statistics.truncated, 0);
    for (int w = 0; w < kWavelengthCount; ++w) {
      double incoming = std::cos(sun_zenith * kDegree) * a.solar_irradiance[w];
      double up = result.sky_irradiance.mean[w], sigma = result.sky_irradiance.standard_error[w];
      Note("energy: sun %g w %d: up %.6g in %.6g ratio %.5f rel.sigma %.2g dev %.2f sigma (%.1f s)\n", sun_zenith, w,
           up, incoming, up / incoming, sigma / incoming, (up - incoming) / sigma, result.statistics.seconds);
      EXPECT_LT(sigma, 0.03 * incoming);
      EXPECT_NEAR(up, incoming, 4.0 * sigma)
          << "sun " << sun_zenith << " wavelength " << w << " (" << (up - incoming) / sigma << " sigma)";
    }
  }
}

// A homogeneous slab (plane-parallel: planet radius 6.36e9 m) of Rayleigh
// and Henyey-Greenstein scatterers with some absorption, over a grey ground.
struct Slab {
  double height = 10e3;
  Spectrum rayleigh{1e-5, 2e-5, 4e-5};
  Spectrum haze{1e-5, 1e-5, 1e-5};
  Spectrum haze_absorption{2e-6, 2e-6, 2e-6};
  double g = 0.6;
  double albedo = 0.3;

  Atmosphere ToAtmosphere() const {
    Atmosphere a = Earth();
    a.name = "slab";
    a.bottom_radius_m = 6360e6;
    a.top_radius_m = a.bottom_radius_m + height;
    a.ground_albedo = Spectrum(albedo);
    a.constituents.resize(2);
    for (Constituent& c : a.constituents) c.density.layers = {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}};
    a.constituents[0].scattering_per_m = rayleigh;
    a.constituents[1].scattering_per_m = haze;
    a.constituents[1].absorption_per_m = haze_absorption;
    a.constituents[1].phase = {PhaseKind::kHenyeyGreenstein, g};
    return a;
  }
};

// Orders 1 and 2 of the slab's radiance by quadrature, in closed form along
// rays: with constant coefficients every transmittance is an exponential.
// L1(z, w): light scattered once into the ray from height z along w (plus,
// when w looks down, the ground's reflection of direct sunlight); the
// camera's order 1 is its in-scattered part, its order 2 the integral along
// the view of T sigma_s,c P_c(w . v) L1(z, w) over all directions w.
class SlabQuadrature {
 public:
  SlabQuadrature(const Slab& slab, const Atmosphere& a, int w, const dvec3& sun)
      : slab_(slab), sun_(sun), e_(a.solar_irradiance[w]) {
    rayleigh_ = slab.rayleigh[w];
    haze_ = slab.haze[w];
    extinction_ = rayleigh_ + haze_ + slab.haze_absorption[w];
  }

  // Scattering coefficient times phase, summed over the two constituents.
  double ScatteringPhase(double cos_theta) const {
    PhaseFunction rayleigh{PhaseKind::kRayleigh, 0.0}, haze{PhaseKind::kHenyeyGreenstein, slab_.g};
    return rayleigh_ * rayleigh.Evaluate(cos_theta) + haze_ * haze.Evaluate(cos_theta);
  }

  double Boundary(double z, const dvec3& w) const {
    return w.z > 0.0 ? (slab_.height - z) / w.z : z / -w.z;
  }

  double InScattered(double z, const dvec3& w) const {
    double mu_s = sun_.z, k = 1.0 - w.z / mu_s;
    double sun = e_ * std::exp(-extinction_ * (slab_.height - z) / mu_s);
    double length = w.z == 0.0 ? std::numeric_limits<double>::infinity() : Boundary(z, w);
    double along = std::abs(k) < 1e-12 ? length : -std::expm1(-extinction_ * k * length) / (extinction_ * k);
    return ScatteringPhase(glm::dot(w, sun_)) * sun * along;
  }

  double OrderOne(double z, const dvec3& w) const {
    double l = InScattered(z, w);
    if (w.z < 0.0) {
      double ground = slab_.albedo / kPi * e_ * sun_.z * std::exp(-extinction_ * slab_.height / sun_.z);
      l += std::exp(-extinction_ * z / -w.z) * ground;
    }
    return l;
  }

  // Order 2 at height z looking along v: integral of T sigma_s P L1.
  double OrderTwo(double z0, const dvec3& v) const {
    const int t_nodes = 48, polar = 96, azimuths = 192;
    std::vector<double> x(polar), wx(polar);
    GaussLegendre(polar, x, wx);
    double length = Boundary(z0, v), sum = 0.0;
    std::vector<double> tx(t_nodes), tw(t_nodes);
    GaussLegendre(t_nodes, tx, tw);
    for (int i = 0; i < t_nodes; ++i) {
      double t = 0.5 * length * (tx[i] + 1.0), z = z0 + t * v.z;
      double inner = 0.0;
      for (int hemisphere = 0; hemisphere < 2; ++hemisphere) {
        for (int j = 0; j < polar; ++j) {
          double cz = 0.5 * (x[j] + 1.0) * (hemisphere ? 1.0 : -1.0), sz = std::sqrt(1.0 - cz * cz);
          for (int k = 0; k < azimuths; ++k) {
            double phi = 2.0 * kPi * (k + 0.5) / azimuths;
            dvec3 w(sz * std::cos(phi), sz * std::sin(phi), cz);
            inner += 0.5 * wx[j] * (2.0 * kPi / azimuths) * ScatteringPhase(glm::dot(w, v)) * OrderOne(z, w);
          }
        }
      }
      sum += 0.5 * length * tw[i] * std::exp(-extinction_ * t) * inner;
    }
    return sum;
  }

 private:
  // Nodes and weights of the n-point Gauss-Legendre rule on [-1, 1] (Newton
  // on the Legendre recurrence).
  static void GaussLegendre(int n, std::vector<double>& x, std::vector<double>& w) {
    for (int i = 0; i < n; ++i) {
      double root = std::cos(kPi * (i + 0.75) / (n + 0.5)), derivative = 0.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = root;
        for (int k = 2; k <= n; ++k) {
          double p2 = ((2.0 * k - 1.0) * root * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = n * (root * p1 - p0) / (root * root - 1.0);
        double step = p1 / derivative;
        root -= step;
        if (std::abs(step) < 1e-15) break;
      }
      x[i] = root;
      w[i] = 2.0 / ((1.0 - root * root) * derivative * derivative);
    }
  }

  Slab slab_;
  dvec3 sun_;
  double e_, rayleigh_ = 0.0, haze_ = 0.0, extinction_ = 0.0;
};

TEST(ReferenceEstimates, SlabOrdersOneAndTwoMatchQuadrature) {
  // Second-order scattering through every part of a path: the forced first
  // continuation, phase sampling of the constituent mixture, free flights,
  // the ground's reflection of sunlight as an event of its own (order 2 =
  // sunlight reflected then scattered once into the view, or scattered
  // twice). Tolerance 4 sigma plus 2e-5 relative for the quadrature
  // (doubling its nodes moves it by less than 2e-8).
  Slab slab;
  Atmosphere a = slab.ToAtmosphere();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(256 * kPathsPerBlock);
  settings.max_order = 2;
  struct Case {
    double altitude, view, sun, azimuth;
  };
  for (Case c : {Case{1000.0, 60.0, 30.0, 60.0}, Case{5000.0, 120.0, 50.0, 150.0}}) {
    RayQuery q = QueryAt(a, c.altitude, c.view, c.sun, c.azimuth);
    Result result = tracer.Evaluate(q, settings, 4);
    for (int w = 0; w < kWavelengthCount; ++w) {
      SlabQuadrature quadrature(slab, a, w, q.sun);
      double one = quadrature.InScattered(c.altitude, q.view), two = quadrature.OrderTwo(c.altitude, q.view);
      double mc = result.radiance.mean[w], sigma = result.radiance.standard_error[w];
      Note("slab: view %g sun %g w %d: mc %.7g quad %.7g (order 2: %.1f%%) rel.sigma %.2g dev %.2f sigma\n", c.view,
           c.sun, w, mc, one + two, 100.0 * two / (one + two), sigma / mc, (mc - one - two) / sigma);
      EXPECT_LT(sigma, 3e-3 * mc);
      EXPECT_NEAR(mc, one + two, 4.0 * sigma + 2e-5 * (one + two)) << "view " << c.view << " wavelength " << w;
    }
  }
}

TEST(ReferenceEstimates, NetFluxIsConstantWithAltitude) {
  // The slab thickened with Earth's Mie (Cornette-Shanks, g = 0.8) and made
  // conservative, over a ground of albedo 0.3: with nothing absorbed in the
  // air and nothing moving sideways on average, the net downward flux
  // (sun + sky from above - sky from below) is the same at the top, inside,
  // and at the ground, where the ground absorbs 1 - albedo of what arrives.
  // Exercises multiple scattering and reflection at every order, the
  // irradiance sampler's sun lobe, and the albedo weighting of bounces.
  Slab slab;
  slab.haze_absorption = Spectrum(0.0);
  slab.albedo = 0.3;
  Atmosphere a = slab.ToAtmosphere();
  a.constituents[0].scattering_per_m *= 3.0;  // vertical optical depth 0.4, 0.7, 1.3
  a.constituents[1].phase = {PhaseKind::kCornetteShanks, 0.8};
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(96 * kPathsPerBlock);
  const double sun_zenith = 40.0;
  const dvec3 up(0.0, 0.0, 1.0), sun(std::sin(sun_zenith * kDegree), 0.0, std::cos(sun_zenith * kDegree));
  auto irradiance = [&](double altitude, const dvec3& normal, Spectrum* sigma) {
    RayQuery q;
    q.camera = dvec3(0.0, 0.0, a.bottom_radius_m + altitude);
    q.view = up;
    q.distance_m = 1e-3;  // no radiance wanted: a millimetre of view ray
    q.sun = sun;
    q.has_normal = true;
    q.normal = normal;
    Result r = tracer.Evaluate(q, settings, static_cast<uint64_t>(altitude) + (normal.z > 0.0 ? 1 : 2));
    *sigma = r.sky_irradiance.standard_error;
    return r.sun_irradiance + r.sky_irradiance.mean;
  };
  Spectrum s_top_up, s_mid_down, s_mid_up, s_ground_down;
  Spectrum top_up = irradiance(slab.height, -up, &s_top_up);
  Spectrum mid_down = irradiance(4000.0, up, &s_mid_down), mid_up = irradiance(4000.0, -up, &s_mid_up);
  Spectrum ground_down = irradiance(0.0, up, &s_ground_down);
  for (int w = 0; w < kWavelengthCount; ++w) {
    double top = sun.z * a.solar_irradiance[w] - top_up[w];
    double middle = mid_down[w] - mid_up[w];
    double ground = (1.0 - slab.albedo) * ground_down[w];
    double sigma_middle = std::hypot(s_mid_down[w], s_mid_up[w]);
    double sigma_ground = (1.0 - slab.albedo) * s_ground_down[w];
    Note("net flux w %d: top %.5g +- %.2g, middle %.5g +- %.2g, ground %.5g +- %.2g\n", w, top, s_top_up[w],
         middle, sigma_middle, ground, sigma_ground);
    EXPECT_NEAR(top, ground, 4.0 * std::hypot(s_top_up[w], sigma_ground)) << w;
    EXPECT_NEAR(middle, ground, 4.0 * std::hypot(sigma_middle, sigma_ground)) << w;
    EXPECT_LT(sigma_ground, 0.02 * ground);
  }
}

TEST(ReferenceEstimates, GroundReflectionIsAnOrder) {
  // Sky irradiance on the ground for a normal pointing down: what the camera
  // receives is the ground's own reflection. At order 1 that is the albedo
  // times the direct sunlight (the reflection is the one event); at order 2
  // it is the albedo times direct sunlight plus order-1 skylight.
  Atmosphere a = Earth();
  a.ground_albedo = Spectrum(0.5);
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(64 * kPathsPerBlock);
  Query down;
  down.sun_zenith_deg = 35.0;
  down.has_normal = true;
  down.normal_zenith_deg = 180.0;
  Query up = down;
  up.normal_zenith_deg = 0.0;
  settings.max_order = 1;
  Result reflected_1 = tracer.Evaluate(down, settings, 1);
  Result sky_1 = tracer.Evaluate(up, settings, 2);
  settings.max_order = 2;
  Result reflected_2 = tracer.Evaluate(down, settings, 3);
  for (int w = 0; w < kWavelengthCount; ++w) {
    double albedo = a.ground_albedo[w];
    EXPECT_NEAR(reflected_1.sky_irradiance.mean[w], albedo * sky_1.sun_irradiance[w],
                4.0 * reflected_1.sky_irradiance.standard_error[w])
        << w;
    double expected = albedo * (sky_1.sun_irradiance[w] + sky_1.sky_irradiance.mean[w]);
    double sigma = std::hypot(reflected_2.sky_irradiance.standard_error[w],
                              albedo * sky_1.sky_irradiance.standard_error[w]);
    EXPECT_NEAR(reflected_2.sky_irradiance.mean[w], expected, 4.0 * sigma) << w;
  }
}

TEST(ReferenceEstimates, StandardErrorShrinksAsOneOverRootN) {
  // Earth, all orders. Standard errors come from B block means; the relative
  // spread of such an estimate is about 1 / sqrt(2 B) for near-Gaussian
  // block means (6% at B = 128, 3% at B = 512), so the ratio of the errors
  // at N and 4N is 2 within ~7%: accept [1.6, 2.5] (about 3 of those
  // sigmas, with room for heavier tails). Independent seeds, so the two
  // means differ by a Gaussian of sigma sqrt(s_N^2 + s_4N^2).
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings small, large;
  small.paths = Scaled(128 * kPathsPerBlock);
  large.paths = 4 * small.paths;
  small.seed = 21;
  large.seed = 22;
  for (RayQuery q : {QueryAt(a, 0.0, 0.0, 30.0, 0.0), QueryAt(a, 0.0, 80.0, 60.0, 120.0)}) {
    Result at_n = tracer.Evaluate(q, small), at_4n = tracer.Evaluate(q, large);
    for (int w = 0; w < kWavelengthCount; ++w) {
      double ratio = at_n.radiance.standard_error[w] / at_4n.radiance.standard_error[w];
      Note("convergence: w %d: stderr ratio %.3f, means %.6g / %.6g (%.2f combined sigma)\n", w, ratio,
           at_n.radiance.mean[w], at_4n.radiance.mean[w],
           (at_n.radiance.mean[w] - at_4n.radiance.mean[w]) /
               std::hypot(at_n.radiance.standard_error[w], at_4n.radiance.standard_error[w]));
      EXPECT_GT(ratio, 1.6) << w;
      EXPECT_LT(ratio, 2.5) << w;
      double combined = std::hypot(at_n.radiance.standard_error[w], at_4n.radiance.standard_error[w]);
      EXPECT_NEAR(at_n.radiance.mean[w], at_4n.radiance.mean[w], 4.0 * combined) << w;
    }
  }
}

TEST(ReferenceEstimates, DeterministicForAnyThreadCount) {
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = 16 * kPathsPerBlock;
  Query query;
  query.view_zenith_deg = 70.0;
  query.sun_zenith_deg = 50.0;
  query.view_sun_azimuth_deg = 30.0;
  query.has_normal = true;
  query.normal_zenith_deg = 20.0;
  settings.threads = 1;
  Result one = tracer.Evaluate(query, settings, 5);
  settings.threads = 2;
  Result two = tracer.Evaluate(query, settings, 5);
  Result again = tracer.Evaluate(query, settings, 5);
  settings.seed = 2;
  Result other_seed = tracer.Evaluate(query, settings, 5);
  Result other_stream = tracer.Evaluate(query, settings, 6);
  for (int w = 0; w < kWavelengthCount; ++w) {
    EXPECT_EQ(one.radiance.mean[w], two.radiance.mean[w]);
    EXPECT_EQ(one.radiance.standard_error[w], two.radiance.standard_error[w]);
    EXPECT_EQ(one.sky_irradiance.mean[w], two.sky_irradiance.mean[w]);
    EXPECT_EQ(one.sky_irradiance.standard_error[w], two.sky_irradiance.standard_error[w]);
    EXPECT_EQ(two.radiance.mean[w], again.radiance.mean[w]);
    EXPECT_NE(two.radiance.mean[w], other_seed.radiance.mean[w]);
    EXPECT_NE(other_seed.radiance.mean[w], other_stream.radiance.mean[w]);
  }
  EXPECT_EQ(one.statistics.vertices, two.statistics.vertices);
}

TEST(ReferenceEstimates, InScatteringAddsUpAlongTheRay) {
  // L(camera, whole ray) = L(camera, first d metres) + T(d) L(point at d,
  // rest of the ray), all orders: checks the distance estimator against the
  // whole-ray one on independent paths (4 sigma of the combined error).
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(64 * kPathsPerBlock);
  for (RayQuery q : {QueryAt(a, 0.0, 75.0, 40.0, 30.0), QueryAt(a, 3000.0, 95.0, 50.0, 150.0)}) {
    const double d = 15000.0;
    RayQuery near = q, far = q;
    near.distance_m = d;
    far.camera = q.camera + d * q.view;
    Result whole = tracer.Evaluate(q, settings, 1);
    Result first = tracer.Evaluate(near, settings, 2);
    Result rest = tracer.Evaluate(far, settings, 3);
    for (int w = 0; w < kWavelengthCount; ++w) {
      double sum = first.radiance.mean[w] + first.transmittance[w] * rest.radiance.mean[w];
      double sigma = std::sqrt(std::pow(whole.radiance.standard_error[w], 2) +
                               std::pow(first.radiance.standard_error[w], 2) +
                               std::pow(first.transmittance[w] * rest.radiance.standard_error[w], 2));
      Note("additivity: w %d: whole %.6g, parts %.6g (%.2f sigma)\n", w, whole.radiance.mean[w], sum,
           (whole.radiance.mean[w] - sum) / sigma);
      EXPECT_NEAR(whole.radiance.mean[w], sum, 4.0 * sigma) << w;
      // Transmittances multiply exactly (to the quadrature's accuracy).
      if (!glsl::RayIntersectsGround(tracer.medium().geometry(), glm::length(q.camera),
                                     glm::dot(q.camera, q.view) / glm::length(q.camera))) {
        EXPECT_NEAR(whole.transmittance[w], first.transmittance[w] * rest.transmittance[w],
                    1e-12 + 1e-9 * whole.transmittance[w]);
      }
    }
  }
}

TEST(ReferenceEstimates, OrdersCountScatteringAndReflections) {
  Atmosphere a = Earth();
  RayQuery q = QueryAt(a, 0.0, 60.0, 45.0, 90.0);
  Settings settings;
  settings.paths = Scaled(32 * kPathsPerBlock);
  auto radiance = [&](const Atmosphere& atmosphere, int max_order) {
    settings.max_order = max_order;
    return PathTracer(atmosphere).Evaluate(q, settings, 9).radiance;
  };
  // With one seed, a run capped at order N traces the same paths as one
  // capped later, cut short: each added order can only add light, exactly.
  Estimate first = radiance(a, 1), second = radiance(a, 2), all = radiance(a, 0);
  for (int w = 0; w < kWavelengthCount; ++w) {
    EXPECT_GT(second.mean[w], first.mean[w]);
    EXPECT_GT(all.mean[w], second.mean[w]);
  }
  // Sunlight reflected by the ground and then scattered into the view is
  // order 2 (the reflection is an event, as in Bruneton's scheme): the ground
  // albedo cannot change order 1, and must add light at order 2.
  Atmosphere black = a, white = a;
  black.ground_albedo = Spectrum(0.0);
  white.ground_albedo = Spectrum(1.0);
  EXPECT_EQ(radiance(black, 1).mean, radiance(white, 1).mean);
  Estimate dark = radiance(black, 2), bright = radiance(white, 2);
  for (int w = 0; w < kWavelengthCount; ++w) {
    double sigma = std::hypot(dark.standard_error[w], bright.standard_error[w]);
    EXPECT_GT(bright.mean[w] - dark.mean[w], 5.0 * sigma) << w;
  }
}

TEST(ReferenceEstimates, SunIrradianceAndEdgeCases) {
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = 2 * kPathsPerBlock;
  // Sun irradiance: E_sun T cos, with T from the independent quadrature.
  Query q;
  q.sun_zenith_deg = 40.0;
  q.view_sun_azimuth_deg = 0.0;
  q.has_normal = true;
  q.normal_zenith_deg = 10.0;
  Result r = tracer.Evaluate(q, settings);
  RayQuery rq = MakeRayQuery(q, a.bottom_radius_m);
  Spectrum tau = BruteOpticalDepth(a, rq.camera, rq.sun, ExitDistance(rq.camera, rq.sun, a.top_radius_m), 4000);
  Spectrum expected = a.solar_irradiance * glm::exp(-tau) * std::cos(30.0 * kDegree);
  for (int w = 0; w < kWavelengthCount; ++w) {
    EXPECT_NEAR(r.sun_irradiance[w], expected[w], 1e-9 * expected[w]);
    EXPECT_LT(r.sun_irradiance_error[w], 1e-8 * expected[w]);
  }
  // From space, looking away from the planet: nothing, full transmittance.
  Query away;
  away.altitude_m = 200e3;
  away.view_zenith_deg = 10.0;
  away.sun_zenith_deg = 30.0;
  Result empty = tracer.Evaluate(away, settings);
  EXPECT_EQ(empty.radiance.mean, Spectrum(0.0));
  EXPECT_EQ(empty.transmittance, Spectrum(1.0));
  // Night (sun 30 degrees below the horizon): finite, non-negative, tiny.
  Query night;
  night.view_zenith_deg = 45.0;
  night.sun_zenith_deg = 120.0;
  Result dark = tracer.Evaluate(night, settings);
  for (int w = 0; w < kWavelengthCount; ++w) {
    EXPECT_GE(dark.radiance.mean[w], 0.0);
    EXPECT_LT(dark.radiance.mean[w], 1e-6);
  }
  // Looking at the ground: transmittance 0 (the ground point is opaque).
  Query down;
  down.altitude_m = 1000.0;
  down.view_zenith_deg = 150.0;
  EXPECT_EQ(tracer.Evaluate(down, settings).transmittance, Spectrum(0.0));
}

TEST(ReferenceEstimates, ThickFogStaysFinite) {
  // Optical depth ~ 100 with single-scattering albedo 0.999: long paths, but
  // finite, non-negative results.
  Atmosphere a = Earth();
  a.constituents.resize(1);
  a.constituents[0].name = "fog";
  a.constituents[0].density.layers = {DensityLayer{1000.0, 0.0, 0.0, 0.0, 1.0}, DensityLayer{}};
  a.constituents[0].scattering_per_m = Spectrum(1e-1);
  a.constituents[0].absorption_per_m = Spectrum(1e-4);
  a.constituents[0].phase = {PhaseKind::kHenyeyGreenstein, 0.8};
  PathTracer tracer(a);
  Settings settings;
  settings.paths = 2 * kPathsPerBlock;
  Query q;
  q.altitude_m = 500.0;
  q.view_zenith_deg = 80.0;
  q.sun_zenith_deg = 30.0;
  q.has_normal = true;
  Result r = tracer.Evaluate(q, settings);
  for (int w = 0; w < kWavelengthCount; ++w) {
    EXPECT_TRUE(std::isfinite(r.radiance.mean[w]) && r.radiance.mean[w] >= 0.0);
    EXPECT_TRUE(std::isfinite(r.sky_irradiance.mean[w]) && r.sky_irradiance.mean[w] >= 0.0);
    EXPECT_GE(r.transmittance[w], 0.0);
  }
}

TEST(ReferenceSettings, RejectsInvalidInput) {
  Settings settings;
  settings.paths = 0;
  EXPECT_THROW(settings.Validate(), InputError);
  settings = Settings();
  settings.max_order = -1;
  EXPECT_THROW(settings.Validate(), InputError);
  settings = Settings();
  settings.threads = -2;
  EXPECT_THROW(settings.Validate(), InputError);
  EXPECT_EQ(Settings().Blocks() * kPathsPerBlock, Settings().paths);
  settings = Settings();
  settings.paths = 1;
  EXPECT_EQ(settings.Blocks(), 2);

  Atmosphere a = Earth();
  a.constituents[0].scattering_per_m.y = -1e-6;
  EXPECT_THROW(PathTracer{a}, InputError);
  a = Earth();
  a.top_radius_m = a.bottom_radius_m;
  EXPECT_THROW(PathTracer{a}, InputError);
  a = Earth();
  a.constituents[1].phase.g = 1.0;
  EXPECT_THROW(PathTracer{a}, InputError);
}

TEST(ReferenceCsv, ParsesQueriesAndWritesResults) {
  const std::string text =
      "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,normal_zenith_deg\n"
      "0,0,30,0,0\n"
      "\n"
      "-5,80,60,90,\n";
  QueryTable table = ParseQueryCsv(text, "q.csv");
  ASSERT_EQ(table.queries.size(), 2u);
  EXPECT_TRUE(table.has_normal);
  EXPECT_FALSE(table.has_distance);
  EXPECT_TRUE(table.queries[0].has_normal);
  EXPECT_FALSE(table.queries[1].has_normal);
  EXPECT_EQ(table.queries[1].altitude_m, 0.0);  // below the ground: on it

  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = 2 * kPathsPerBlock;
  std::vector<Result> results;
  for (size_t i = 0; i < table.queries.size(); ++i) results.push_back(tracer.Evaluate(table.queries[i], settings, i));
  std::string csv = FormatResultCsv(table, results, a.wavelengths_nm);
  std::string header = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(header,
            "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,normal_zenith_deg,"
            "radiance_680nm,radiance_550nm,radiance_440nm,"
            "radiance_stderr_680nm,radiance_stderr_550nm,radiance_stderr_440nm,"
            "transmittance_680nm,transmittance_550nm,transmittance_440nm,"
            "sun_irradiance_680nm,sun_irradiance_550nm,sun_irradiance_440nm,"
            "sky_irradiance_680nm,sky_irradiance_550nm,sky_irradiance_440nm,"
            "sky_irradiance_stderr_680nm,sky_irradiance_stderr_550nm,sky_irradiance_stderr_440nm,"
            "transmittance_error_680nm,transmittance_error_550nm,transmittance_error_440nm");
  // Every row has as many fields as the header.
  size_t columns = std::count(header.begin(), header.end(), ',') + 1;
  size_t begin = csv.find('\n') + 1;
  int rows = 0;
  while (begin < csv.size()) {
    size_t end = csv.find('\n', begin);
    std::string row = csv.substr(begin, end - begin);
    EXPECT_EQ(std::count(row.begin(), row.end(), ',') + 1, static_cast<long>(columns)) << row;
    begin = end + 1;
    ++rows;
  }
  EXPECT_EQ(rows, 2);

  auto fails = [](const std::string& bad, const std::string& message) {
    try {
      ParseQueryCsv(bad, "q.csv");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  fails("", "empty query file");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg\n", "missing column 'view_sun_azimuth_deg'");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,colour\n", "q.csv:1: unknown column");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,190,30,0\n",
        "q.csv:2: view_zenith_deg = 190 is outside [0, 180]");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,distance_m\n0,10,30,0,-1\n",
        "distance_m = -1 is negative");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,x,30,0\n", "is not a number");
  fails("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,10,30\n", "expected 4 fields, got 3");
}

}  // namespace
}  // namespace skybake::reference
