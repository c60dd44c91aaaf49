// The geometry of a `skybake eval` query, shared by every tool that answers
// queries (eval, the reference solver, the GL tests): planet centre at the
// origin, camera at (0, 0, ground_radius + altitude), view direction
// (sin vz, 0, cos vz), sun direction (sin sz cos az, sin sz sin az, cos sz),
// surface normal tilted from the zenith toward the sun's azimuth.
#pragma once

#include <cmath>

#include "shaders_runtime/glsl_shim.h"

namespace skybake {

struct Query {
  double altitude_m = 0.0;
  double view_zenith_deg = 0.0;
  double sun_zenith_deg = 0.0;
  double view_sun_azimuth_deg = 0.0;
  double distance_m = 0.0;  // 0: the whole ray (sky); > 0: to the point at that distance
  bool has_normal = false;
  double normal_zenith_deg = 0.0;
};

struct QueryGeometry {
  glsl::vec3 camera;
  glsl::vec3 view;
  glsl::vec3 sun;
  glsl::vec3 normal;
};

inline QueryGeometry MakeQueryGeometry(const Query& q, double bottom_radius_m) {
  constexpr double kDegree = kPi / 180.0;
  double vz = q.view_zenith_deg * kDegree, sz = q.sun_zenith_deg * kDegree;
  double az = q.view_sun_azimuth_deg * kDegree, nz = q.normal_zenith_deg * kDegree;
  QueryGeometry g;
  g.camera = glsl::vec3(0.0, 0.0, bottom_radius_m + q.altitude_m);
  g.view = glsl::vec3(std::sin(vz), 0.0, std::cos(vz));
  g.sun = glsl::vec3(std::sin(sz) * std::cos(az), std::sin(sz) * std::sin(az), std::cos(sz));
  g.normal = glsl::vec3(std::sin(nz) * std::cos(az), std::sin(nz) * std::sin(az), std::cos(nz));
  return g;
}

}  // namespace skybake
