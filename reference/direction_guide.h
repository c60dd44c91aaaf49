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

// A point's local frame: its zenith, and the horizontal direction toward the
// sun's azimuth and the one across it. The light field is symmetric about
// the axis through the planet's centre toward the sun, so a guide built at
// one point serves every point at the same radius and sun cosine, in that
// point's own frame.
struct GuideFrame {
  glm::dvec3 zenith{0.0, 0.0, 1.0}, toward_sun{1.0, 0.0, 0.0}, across{0.0, 1.0, 0.0};
  GuideFrame() = default;
  GuideFrame(const glm::dvec3& point, const glm::dvec3& sun);
};

class DirectionGuide {
 public:
  // The radiance estimate at radius r where the sun's zenith cosine is mu_s,
  // wavelength w.
  DirectionGuide(const LayeredMedium& medium, const SunlightTable& sunlight, double r, double mu_s, int w);

  // False where no direction sees lit air: then it must not be sampled.
  bool usable() const { return total_ > 0.0; }

  // A direction in `frame` from three uniform numbers in [0, 1).
  glm::dvec3 Sample(const GuideFrame& frame, double u_cell, double u1, double u2) const;

  // Its density per steradian.
  double Pdf(const GuideFrame& frame, const glm::dvec3& direction) const;

  // The estimate's integral over the sphere: the single-scattered light
  // arriving at the point from all directions (per unit solar irradiance).
  double Incoming() const { return total_ * kCellSolidAngle; }

 private:
  static constexpr int kZenithCells = 32, kAzimuthCells = 32, kSteps = 32;
  // Each cell spans 2 / kZenithCells in cosine and 2 pi / kAzimuthCells.
  static constexpr double kCellSolidAngle = (2.0 / kZenithCells) * (2.0 * kPi / kAzimuthCells);
  std::vector<double> cumulative_;  // per cell, azimuth fastest
  std::vector<double> value_;
  double total_ = 0.0;
};

// Guides at altitudes x sun cosines, built once per atmosphere and
// wavelength for the twilight sky; a point uses the nearest.
class DirectionGuideField {
 public:
  DirectionGuideField(const LayeredMedium& medium, const SunlightTable& sunlight, int w);
  // The guide for radius r and sun cosine mu_s, or null where it is not usable.
  const DirectionGuide* At(double r, double mu_s) const;

 private:
  // Altitudes top_height (i / (kAltitudes - 1))^2, sun cosines in
  // [kMinCosine, kMaxCosine] (sun zenith 105 to 78 degrees).
  static constexpr int kAltitudes = 8, kCosines = 14;
  static constexpr double kMinCosine = -0.26, kMaxCosine = 0.2;
  double bottom_ = 0.0, height_ = 0.0;
  std::vector<DirectionGuide> guides_;  // kCosines per altitude
};

}  // namespace skybake::reference
