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
#include "test_atmospheres.h"

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

using testing::Earth;

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
