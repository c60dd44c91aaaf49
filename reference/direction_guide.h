// Where single-scattered light comes from, seen from one point: a density
// over directions proportional to an estimate of the radiance scattered
// once toward the point from each direction, on a grid in (cos zenith,
// azimuth from the sun). After sunset most directions see only shadowed
// air, and a path that chooses its next direction by the phase function
// alone rarely heads for the lit air hundreds of kilometres toward the sun;
// mixed with phase sampling (Tracer::Trace), this density sends it there.
// It only shapes what is sampled: every estimate uses the exact phase
// function and sunlight, so its crude estimate costs variance, never bias.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "core/constants.h"
#include "reference/layered_medium.h"
#include "reference/sunlight_table.h"

namespace skybake::reference {

class DirectionGuide {
 public:
  // The radiance estimate at `point` for the sun along `sun`, wavelength w.
  DirectionGuide(const LayeredMedium& medium, const SunlightTable& sunlight, const glm::dvec3& point,
                 const glm::dvec3& sun, int w);

  // False where no direction sees lit air: then it must not be sampled.
  bool usable() const { return total_ > 0.0; }

  // A direction from three uniform numbers in [0, 1).
  glm::dvec3 Sample(double u_cell, double u1, double u2) const;

  // Its density per steradian.
  double Pdf(const glm::dvec3& direction) const;

  // The estimate's integral over the sphere: the single-scattered light
  // arriving at the point from all directions (per unit solar irradiance).
  double Incoming() const { return total_ * kCellSolidAngle; }

  const glm::dvec3& point() const { return point_; }

 private:
  static constexpr int kZenithCells = 32, kAzimuthCells = 32, kSteps = 32;
  // Each cell spans 2 / kZenithCells in cosine and 2 pi / kAzimuthCells.
  static constexpr double kCellSolidAngle = (2.0 / kZenithCells) * (2.0 * kPi / kAzimuthCells);
  glm::dvec3 point_{0.0};
  glm::dvec3 zenith_{0.0, 0.0, 1.0}, x_axis_{1.0, 0.0, 0.0}, y_axis_{0.0, 1.0, 0.0};
  std::vector<double> cumulative_;  // per cell, azimuth fastest
  std::vector<double> value_;
  double total_ = 0.0;
};

}  // namespace skybake::reference
