#include "report/ray_march.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "core/errors.h"

namespace skybake::report {

bool IntersectSphere(const glm::dvec3& origin, const glm::dvec3& direction, double radius, double* near,
                     double* far) {
  // t^2 + 2 b t + c = 0.
  double b = glm::dot(origin, direction);
  double c = glm::dot(origin, origin) - radius * radius;
  double discriminant = b * b - c;
  if (discriminant < 0.0) return false;
  double q = -(b + std::copysign(std::sqrt(discriminant), b));
  double t1 = q, t2 = q != 0.0 ? c / q : 0.0;
  *near = std::min(t1, t2);
  *far = std::max(t1, t2);
  return true;
}

SingleScatteringRayMarch::SingleScatteringRayMarch(const Atmosphere& atmosphere, int view_steps, int light_steps)
    : atmosphere_(atmosphere), view_steps_(view_steps), light_steps_(light_steps) {
  if (view_steps < 1 || light_steps < 1) throw InternalError("ray march: step counts must be at least 1");
}

void SingleScatteringRayMarch::Coefficients(double altitude_m, double cos_theta, glm::dvec3* extinction,
                                            glm::dvec3* angular) const {
  *extinction = glm::dvec3(0.0);
  if (angular) *angular = glm::dvec3(0.0);
  for (const Constituent& c : atmosphere_.constituents) {
    double density = c.density.At(altitude_m);
    *extinction += density * c.Extinction();
    if (angular) *angular += density * c.scattering_per_m * c.phase.Evaluate(cos_theta);
  }
}

bool SingleScatteringRayMarch::SunOpticalDepth(const glm::dvec3& point, const glm::dvec3& sun, glm::dvec3* depth,
                                               long* samples) const {
  double near, far;
  if (IntersectSphere(point, sun, atmosphere_.bottom_radius_m, &near, &far) && far > 0.0) return false;
  if (!IntersectSphere(point, sun, atmosphere_.top_radius_m, &near, &far) || far <= 0.0) {
    *depth = glm::dvec3(0.0);
    return true;
  }
  double dt = far / light_steps_;
  *depth = glm::dvec3(0.0);
  for (int i = 0; i < light_steps_; ++i) {
    glm::dvec3 x = point + sun * ((i + 0.5) * dt);
    glm::dvec3 extinction;
    Coefficients(glm::length(x) - atmosphere_.bottom_radius_m, 0.0, &extinction, nullptr);
    *depth += extinction * dt;
  }
  if (samples) *samples += light_steps_;
  return true;
}

glm::dvec3 SingleScatteringRayMarch::Radiance(const glm::dvec3& camera, const glm::dvec3& view,
                                              const glm::dvec3& sun, double distance_m, glm::dvec3* transmittance,
                                              long* density_samples) const {
  if (transmittance) *transmittance = glm::dvec3(1.0);
  // The part of the ray inside the atmosphere, ended by the ground.
  double start, end;
  if (!IntersectSphere(camera, view, atmosphere_.top_radius_m, &start, &end) || end <= 0.0) return glm::dvec3(0.0);
  start = std::max(start, 0.0);
  double ground_near, ground_far;
  if (IntersectSphere(camera, view, atmosphere_.bottom_radius_m, &ground_near, &ground_far) && ground_near > 0.0) {
    end = std::min(end, ground_near);
  }
  if (distance_m > 0.0) end = std::min(end, distance_m);
  if (end <= start) return glm::dvec3(0.0);

  const double cos_theta = glm::dot(view, sun);
  const double dt = (end - start) / view_steps_;
  glm::dvec3 depth(0.0), radiance(0.0);
  for (int i = 0; i < view_steps_; ++i) {
    glm::dvec3 x = camera + view * (start + (i + 0.5) * dt);
    glm::dvec3 extinction, angular;
    Coefficients(glm::length(x) - atmosphere_.bottom_radius_m, cos_theta, &extinction, &angular);
    if (density_samples) ++*density_samples;
    glm::dvec3 sun_depth;
    if (SunOpticalDepth(x, sun, &sun_depth, density_samples)) {
      radiance += angular * glm::exp(-(depth + 0.5 * dt * extinction + sun_depth)) * dt;
    }
    depth += extinction * dt;
  }
  if (transmittance) *transmittance = glm::exp(-depth);
  return radiance * atmosphere_.solar_irradiance;
}

glm::dvec3 SingleScatteringRayMarch::SunIrradiance(const glm::dvec3& point, const glm::dvec3& normal,
                                                   const glm::dvec3& sun, long* density_samples) const {
  glm::dvec3 depth;
  if (!SunOpticalDepth(point, sun, &depth, density_samples)) return glm::dvec3(0.0);
  return atmosphere_.solar_irradiance * glm::exp(-depth) * std::max(glm::dot(normal, sun), 0.0);
}

}  // namespace skybake::report
