// Validation of the reference solver's Monte Carlo estimates (reference/)
// against an independent single-scattering quadrature, energy conservation
// and its own invariants (orders, standard errors, determinism), and of its
// settings and query files. The sampling routines and deterministic
// integrals are in reference_sampling_test.cpp, the slab cases in
// reference_slab_test.cpp; tolerances: see reference_test_util.h.
#include <algorithm>
#include <cmath>
#include <cstdint>
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
#include "reference/query_csv.h"
#include "reference/random.h"
#include "shaders_runtime/runtime.h"
#include "reference_test_util.h"

namespace skybake::reference {
namespace {

using glm::dvec3;

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

TEST(ReferenceEstimates, SingleScatteringMatchesIndependentQuadrature) {
  // max_order = 1 on Earth against BruteSingleScattering. Only the first
  // vertex's distance is random (stratified), so the standard errors are
  // small (1e-4 to 2e-3 relative) and the check is sharp. Tolerance: 5 sigma
  // (27 comparisons, each a t statistic with 63 degrees of freedom: ~1e-4
  // chance of a false alarm in all) plus 2e-5 relative for the quadrature,
  // whose panels are converged to 2e-8 (quadrupling them moves it by less). Over
  // 100 seeds the deviations had mean -0.1 and rms 1.0 sigma.
  Atmosphere a = Earth();
  PathTracer tracer(a);
  Settings settings;
  settings.paths = Scaled(4096);
  settings.max_order = 1;
  // Where the sun sets along the ray the integrand has a steep edge, which
  // the guided distances follow.
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
      {2000.0, 80.0, 92.0, 0.0, 0.0, 2e-3},      // sun below the camera's horizon, lit further on
      {0.0, 85.0, 90.1, 0.0, 0.0, 2e-3},         // sun disc straddling the horizon
      // Twilight: only a high shell is lit, which the view ray's distances
      // are guided to (SunlightTable).
      {0.0, 0.0, 96.0, 0.0, 0.0, 2e-3},        // zenith, lit above ~35 km
      {0.0, 85.0, 98.0, 0.0, 0.0, 2e-3},       // toward the sun
      {10000.0, 60.0, 98.0, 0.0, 0.0, 2e-3},   // from 10 km
      {0.0, 85.0, 100.0, 0.0, 0.0, 2e-3},      // deep twilight
      {0.0, 85.0, 101.5, 0.0, 0.0, 1e-2},      // the last lit air, 1e-13 of daylight
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
  // Views whose whole ray lies in the Earth's shadow: exactly dark.
  for (double sun : {96.0, 100.0}) {
    RayQuery q = QueryAt(a, 0.0, 85.0, sun, 180.0);
    EXPECT_EQ(BruteSingleScattering(a, q, 400), Spectrum(0.0)) << sun;
    EXPECT_EQ(tracer.Evaluate(q, settings, 11).radiance.mean, Spectrum(0.0)) << sun;
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
  std::string csv = FormatResultCsv(table, results, WavelengthChannels(a.wavelengths_nm));
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
