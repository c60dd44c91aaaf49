// Where scattered light comes from, seen from one point: a density over
// directions proportional to an estimate of the radiance scattered toward
// the point from each direction, on a grid in (cos zenith, azimuth from the
// sun) whose zenith cells narrow toward the point's horizon, where the lit
// air is seen after sunset. Then most directions see only shadowed
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

class DirectionGuideField;

class DirectionGuide {
 public:
  // The radiance estimate at radius r where the sun's zenith cosine is mu_s,
  // wavelength w: light scattered once toward the point, plus, given the
  // field of single-scattered light, that light scattered once more
  // (isotropically, from the field's total at each point), so that the
  // paths of higher orders, most of the light deep in twilight, are guided
  // too.
  DirectionGuide(const LayeredMedium& medium, const SunlightTable& sunlight, const DirectionGuideField* single,
                 double r, double mu_s, int w);
  DirectionGuide() = default;  // sees no lit air

  // False where no direction sees lit air: then it must not be sampled.
  bool usable() const { return total_ > 0.0; }

  // A direction in `frame` from three uniform numbers in [0, 1).
  glm::dvec3 Sample(const GuideFrame& frame, double u_cell, double u1, double u2) const;

  // Its density per steradian.
  double Pdf(const GuideFrame& frame, const glm::dvec3& direction) const;

  // The estimate's integral over the sphere: the light it estimates
  // arriving at the point from all directions (per unit solar irradiance).
  double Incoming() const { return total_; }

 private:
  // Zenith cells above and below the horizon; the edges lie at
  // mu_h + (1 - mu_h) x^2 above it and mu_h - (1 + mu_h) x^2 below, x
  // uniform, so that the cells next to the horizon (mu_h) span about 0.03
  // degrees.
  static constexpr int kCellsAbove = 48, kCellsBelow = 16, kZenithCells = kCellsAbove + kCellsBelow;
  static constexpr int kAzimuthCells = 32, kSteps = 64;
  static constexpr double kAzimuthWidth = 2.0 * kPi / kAzimuthCells;
  int ZenithCell(double cos_zenith) const;
  std::vector<double> cos_edges_;   // kZenithCells + 1, ascending from -1 to 1
  std::vector<double> value_;       // radiance estimate per cell, azimuth fastest
  std::vector<double> cumulative_;  // running sum of value x solid angle
  double total_ = 0.0;
};

// The guides of the field around one point: a mixture of up to four
// neighbours in altitude and sun cosine, weighted bilinearly, so that the
// density follows the point smoothly.
class GuideMixture {
 public:
  bool usable() const { return count_ > 0; }
  glm::dvec3 Sample(const GuideFrame& frame, double u_guide, double u_cell, double u1, double u2) const;
  double Pdf(const GuideFrame& frame, const glm::dvec3& direction) const;
  double Incoming() const;

 private:
  friend class DirectionGuideField;
  void Add(const DirectionGuide& guide, double weight);
  const DirectionGuide* guides_[4] = {};
  double weights_[4] = {};
  int count_ = 0;
};

// Guides at altitudes x sun cosines, built once per atmosphere and
// wavelength for the twilight sky; a point mixes its four neighbours.
class DirectionGuideField {
 public:
  // Guides of single-scattered light, and with `single`, the guides of
  // DirectionGuide that add the light scattered twice.
  DirectionGuideField(const LayeredMedium& medium, const SunlightTable& sunlight, const DirectionGuideField* single,
                      int w);
  // The usable guides around radius r and sun cosine mu_s (none: not usable).
  GuideMixture At(double r, double mu_s) const;

 private:
  // Altitudes top_height (i / (kAltitudes - 1))^2, sun cosines in
  // [kMinCosine, kMaxCosine] (sun zenith 105 to 78 degrees, about 1 degree
  // apart).
  static constexpr int kAltitudes = 16, kCosines = 28;
  static constexpr double kMinCosine = -0.26, kMaxCosine = 0.2;
  double bottom_ = 0.0, height_ = 0.0;
  std::vector<DirectionGuide> guides_;  // kCosines per altitude
};

}  // namespace skybake::reference
