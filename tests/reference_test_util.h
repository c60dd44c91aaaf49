// Helpers shared by the tests of the reference solver (reference/):
// reference_sampling_test.cpp, reference_test.cpp and reference_slab_test.cpp.
//
// Monte Carlo tolerances are stated in standard errors (sigma). Seeds are
// fixed, so every test is deterministic; the tolerances are set so that a
// correct solver passes for the vast majority of seeds (4 sigma: 6e-5 two-sided
// for a Gaussian), while the errors they guard against (a missing factor,
// a wrong phase normalisation, a biased sampler) move the estimate by tens
// or hundreds of sigma. SKYBAKE_REFERENCE_TEST_SCALE=k multiplies the path
// counts by k, to rerun the same checks at higher precision;
// SKYBAKE_REFERENCE_TEST_VERBOSE=1 prints the measured figures.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "bake/atmosphere.h"
#include "core/constants.h"
#include "reference/path_tracer.h"
#include "reference/query_csv.h"

namespace skybake::reference {

inline constexpr double kDegree = kPi / 180.0;

inline int64_t Scaled(int64_t paths) {
  const char* scale = std::getenv("SKYBAKE_REFERENCE_TEST_SCALE");
  return scale ? paths * std::max(1, std::atoi(scale)) : paths;
}

inline void Note(const char* format, ...) {
  if (!std::getenv("SKYBAKE_REFERENCE_TEST_VERBOSE")) return;
  va_list args;
  va_start(args, format);
  std::vprintf(format, args);
  va_end(args);
}

// Earth, with the parameter values of DESIGN.md (Bruneton's 2017 set).
inline Atmosphere Earth() {
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

// The query at `altitude` looking at `view_zenith` with the sun at
// `sun_zenith` and `azimuth` between them (degrees), as a ray.
inline RayQuery QueryAt(const Atmosphere& a, double altitude, double view_zenith, double sun_zenith, double azimuth,
                 double distance = 0.0) {
  Query q;
  q.altitude_m = altitude;
  q.view_zenith_deg = view_zenith;
  q.sun_zenith_deg = sun_zenith;
  q.view_sun_azimuth_deg = azimuth;
  q.distance_m = distance;
  return MakeRayQuery(q, a.bottom_radius_m);
}

}  // namespace skybake::reference
