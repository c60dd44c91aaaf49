#include "reference/direction_guide.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/constants.h"
#include "reference/ray_segment.h"
#include "shaders_runtime/runtime.h"

namespace skybake::reference {

using glm::dvec3;

GuideFrame::GuideFrame(const dvec3& point, const dvec3& sun) : zenith(glm::normalize(point)) {
  dvec3 horizontal = sun - glm::dot(sun, zenith) * zenith;
  if (glm::length(horizontal) < 1e-9) {
    horizontal = std::abs(zenith.x) < 0.9 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 1.0, 0.0);
    horizontal -= glm::dot(horizontal, zenith) * zenith;
  }
  toward_sun = glm::normalize(horizontal);
  across = glm::cross(zenith, toward_sun);
}

DirectionGuide::DirectionGuide(const LayeredMedium& medium, const SunlightTable& sunlight, double r, double mu_s,
                               int w) {
  const glsl::AtmosphereParameters& g = medium.geometry();
  // A canonical point and sun with that radius and sun cosine.
  const double r0 = std::clamp(r, g.bottom_radius, g.top_radius);
  const dvec3 start(0.0, 0.0, r0);
  const dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
  const GuideFrame frame(start, sun);
  std::vector<double> sigma(medium.constituent_count());
  value_.assign(kZenithCells * kAzimuthCells, 0.0);
  for (int i = 0; i < kZenithCells; ++i) {
    const double cos_zenith = -1.0 + 2.0 * (i + 0.5) / kZenithCells;
    const double sin_zenith = std::sqrt(std::max(0.0, 1.0 - cos_zenith * cos_zenith));
    double t_in = 0.0, length = 0.0;
    if (!InsideTopSphere(g, r0, cos_zenith, &t_in, &length)) continue;
    if (glsl::RayIntersectsGround(g, r0, cos_zenith)) length = glsl::DistanceToBottomAtmosphereBoundary(g, r0, cos_zenith);
    const double dt = (length - t_in) / kSteps;
    for (int j = 0; j < kAzimuthCells; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / kAzimuthCells;
      const dvec3 direction = sin_zenith * (std::cos(phi) * frame.toward_sun + std::sin(phi) * frame.across) +
                              cos_zenith * frame.zenith;
      // Light scattered once toward the point along the cell's central
      // direction: the midpoint rule, transmittance by the same rule.
      const double cos_scattering = -glm::dot(direction, sun);
      double depth = 0.0, radiance = 0.0;
      for (int k = 0; k < kSteps; ++k) {
        const dvec3 x = start + (t_in + (k + 0.5) * dt) * direction;
        const double r = glm::length(x);
        const double extinction = medium.Extinction(r, w);
        medium.Scattering(r, w, sigma.data());
        double phase = 0.0;
        for (int c = 0; c < medium.constituent_count(); ++c) {
          if (sigma[c] > 0.0) phase += sigma[c] * medium.phase(c).Evaluate(cos_scattering);
        }
        radiance += std::exp(-(depth + 0.5 * extinction * dt)) * phase * sunlight.At(r, glm::dot(x, sun) / r)[w] * dt;
        depth += extinction * dt;
      }
      value_[i * kAzimuthCells + j] = radiance;
    }
  }
  cumulative_.resize(value_.size());
  for (std::size_t c = 0; c < value_.size(); ++c) {
    total_ += value_[c];
    cumulative_[c] = total_;
  }
}

dvec3 DirectionGuide::Sample(const GuideFrame& frame, double u_cell, double u1, double u2) const {
  std::size_t cell = static_cast<std::size_t>(
      std::upper_bound(cumulative_.begin(), cumulative_.end(), u_cell * total_) - cumulative_.begin());
  cell = std::min(cell, cumulative_.size() - 1);
  while (cell > 0 && !(value_[cell] > 0.0)) --cell;  // a u on the last edge
  const int i = static_cast<int>(cell) / kAzimuthCells, j = static_cast<int>(cell) % kAzimuthCells;
  const double cos_zenith = std::clamp(-1.0 + 2.0 * (i + u1) / kZenithCells, -1.0, 1.0);
  const double sin_zenith = std::sqrt(std::max(0.0, 1.0 - cos_zenith * cos_zenith));
  const double phi = 2.0 * kPi * (j + u2) / kAzimuthCells;
  return sin_zenith * (std::cos(phi) * frame.toward_sun + std::sin(phi) * frame.across) + cos_zenith * frame.zenith;
}

double DirectionGuide::Pdf(const GuideFrame& frame, const dvec3& direction) const {
  const double cos_zenith = std::clamp(glm::dot(direction, frame.zenith), -1.0, 1.0);
  double phi = std::atan2(glm::dot(direction, frame.across), glm::dot(direction, frame.toward_sun));
  if (phi < 0.0) phi += 2.0 * kPi;
  const int i = std::clamp(static_cast<int>((cos_zenith + 1.0) * 0.5 * kZenithCells), 0, kZenithCells - 1);
  const int j = std::clamp(static_cast<int>(phi / (2.0 * kPi) * kAzimuthCells), 0, kAzimuthCells - 1);
  return value_[i * kAzimuthCells + j] / (total_ * kCellSolidAngle);
}

DirectionGuideField::DirectionGuideField(const LayeredMedium& medium, const SunlightTable& sunlight, int w)
    : bottom_(medium.bottom_radius()), height_(medium.top_radius() - medium.bottom_radius()) {
  for (int i = 0; i < kAltitudes; ++i) {
    const double x = double(i) / (kAltitudes - 1);
    for (int j = 0; j < kCosines; ++j) {
      const double mu_s = kMinCosine + (kMaxCosine - kMinCosine) * j / (kCosines - 1);
      guides_.emplace_back(medium, sunlight, bottom_ + height_ * x * x, mu_s, w);
    }
  }
}

const DirectionGuide* DirectionGuideField::At(double r, double mu_s) const {
  const double x = std::sqrt(std::clamp((r - bottom_) / height_, 0.0, 1.0)) * (kAltitudes - 1);
  const double y = (std::clamp(mu_s, kMinCosine, kMaxCosine) - kMinCosine) / (kMaxCosine - kMinCosine) * (kCosines - 1);
  const DirectionGuide& guide = guides_[static_cast<std::size_t>(std::lround(x)) * kCosines + std::lround(y)];
  return guide.usable() ? &guide : nullptr;
}

}  // namespace skybake::reference
