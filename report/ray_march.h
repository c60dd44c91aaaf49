// A per-pixel single-scattering ray march, the cheap run-time baseline of
// `skybake report` (O'Neil, GPU Gems 2 ch. 16; the codeflow WebGL sky): N
// midpoint steps along the view ray, and from each an M-step march toward
// the sun for its transmittance; no tables, no multiple scattering.
//
// It lives here, in C++ only, because it is measured, not shipped: the
// engine snippet samples tables. It reads the Atmosphere's own density
// profiles and phase functions, so it answers for every constituent the
// bake knows (ozone included), with the step count as its only knob.
#pragma once

#include <glm/vec3.hpp>

#include "bake/atmosphere.h"

namespace skybake::report {

class SingleScatteringRayMarch {
 public:
  // `view_steps` and `light_steps` >= 1.
  SingleScatteringRayMarch(const Atmosphere& atmosphere, int view_steps, int light_steps);

  // Positions relative to the planet centre (metres), unit directions.
  // `distance_m` > 0: to the point at that distance (aerial perspective);
  // 0: to the atmosphere's boundary or the ground. `density_samples`, if
  // given, is increased by the number of points where the densities were
  // evaluated (the loop iterations, view and light steps together).
  glm::dvec3 Radiance(const glm::dvec3& camera, const glm::dvec3& view, const glm::dvec3& sun, double distance_m,
                      glm::dvec3* transmittance, long* density_samples = nullptr) const;
  // Direct sunlight on a surface: the light march alone.
  glm::dvec3 SunIrradiance(const glm::dvec3& point, const glm::dvec3& normal, const glm::dvec3& sun,
                           long* density_samples = nullptr) const;

 private:
  // Scattering and extinction coefficients at a point (m^-1, per channel),
  // and the angular scattering (phase-weighted) toward `cos_theta`.
  void Coefficients(double altitude_m, double cos_theta, glm::dvec3* extinction, glm::dvec3* angular) const;
  // Optical depth from `point` toward `sun` to the top; false if the ground is in the way.
  bool SunOpticalDepth(const glm::dvec3& point, const glm::dvec3& sun, glm::dvec3* depth, long* samples) const;

  Atmosphere atmosphere_;
  int view_steps_, light_steps_;
};

// The distances (near, far) at which the ray origin + t * direction (unit)
// crosses the sphere of `radius` about the origin; false if it misses.
// Written without the cancellation of -b +- sqrt(b^2 - c) for grazing rays.
bool IntersectSphere(const glm::dvec3& origin, const glm::dvec3& direction, double radius, double* near, double* far);

}  // namespace skybake::report
