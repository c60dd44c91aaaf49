#include "reference/direction_guide.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

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

DirectionGuide::DirectionGuide(const LayeredMedium& medium, const SunlightTable& sunlight,
                               const DirectionGuideField* single, double r, double mu_s, int w) {
  const glsl::AtmosphereParameters& g = medium.geometry();
  // A canonical point and sun with that radius and sun cosine.
  const double r0 = std::clamp(r, g.bottom_radius, g.top_radius);
  const dvec3 start(0.0, 0.0, r0);
  const dvec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
  const GuideFrame frame(start, sun);
  const double ratio = g.bottom_radius / r0;
  const double mu_horizon = -std::sqrt(std::max(0.0, 1.0 - ratio * ratio));
  cos_edges_.resize(kZenithCells + 1);
  for (int i = 0; i <= kCellsBelow; ++i) {
    const double x = double(kCellsBelow - i) / kCellsBelow;
    cos_edges_[i] = mu_horizon - (1.0 + mu_horizon) * x * x;
  }
  for (int i = 1; i <= kCellsAbove; ++i) {
    const double x = double(i) / kCellsAbove;
    cos_edges_[kCellsBelow + i] = mu_horizon + (1.0 - mu_horizon) * x * x;
  }
  std::vector<double> sigma(medium.constituent_count());
  value_.assign(kZenithCells * kAzimuthCells, 0.0);
  for (int i = 0; i < kZenithCells; ++i) {
    const double cos_zenith = 0.5 * (cos_edges_[i] + cos_edges_[i + 1]);
    const double sin_zenith = std::sqrt(std::max(0.0, 1.0 - cos_zenith * cos_zenith));
    double t_in = 0.0, length = 0.0;
    if (!InsideTopSphere(g, r0, cos_zenith, &t_in, &length)) continue;
    if (glsl::RayIntersectsGround(g, r0, cos_zenith)) length = glsl::DistanceToBottomAtmosphereBoundary(g, r0, cos_zenith);
    const double dt = (length - t_in) / kSteps;
    // The field is symmetric about the plane of the zenith and the sun:
    // azimuth cell j mirrors cell kAzimuthCells - 1 - j.
    for (int j = 0; j < kAzimuthCells / 2; ++j) {
      const double phi = kAzimuthWidth * (j + 0.5);
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
        const double mu_s_x = glm::dot(x, sun) / r;
        double phase = 0.0, scattering = 0.0;
        for (int c = 0; c < medium.constituent_count(); ++c) {
          if (!(sigma[c] > 0.0)) continue;
          phase += sigma[c] * medium.phase(c).Evaluate(cos_scattering);
          scattering += sigma[c];
        }
        double source = phase * sunlight.At(r, mu_s_x)[w];
        if (single) {
          const GuideMixture around = single->At(r, mu_s_x);
          if (around.usable()) source += scattering * around.Incoming() / (4.0 * kPi);
        }
        radiance += std::exp(-(depth + 0.5 * extinction * dt)) * source * dt;
        depth += extinction * dt;
      }
      value_[i * kAzimuthCells + j] = radiance;
      value_[i * kAzimuthCells + kAzimuthCells - 1 - j] = radiance;
    }
  }
  cumulative_.resize(value_.size());
  for (std::size_t c = 0; c < value_.size(); ++c) {
    const std::size_t i = c / kAzimuthCells;
    total_ += value_[c] * (cos_edges_[i + 1] - cos_edges_[i]) * kAzimuthWidth;
    cumulative_[c] = total_;
  }
}

int DirectionGuide::ZenithCell(double cos_zenith) const {
  const auto edge = std::upper_bound(cos_edges_.begin() + 1, cos_edges_.end() - 1, cos_zenith);
  return static_cast<int>(edge - cos_edges_.begin()) - 1;
}

dvec3 DirectionGuide::Sample(const GuideFrame& frame, double u_cell, double u1, double u2) const {
  std::size_t cell = static_cast<std::size_t>(
      std::upper_bound(cumulative_.begin(), cumulative_.end(), u_cell * total_) - cumulative_.begin());
  cell = std::min(cell, cumulative_.size() - 1);
  while (cell > 0 && !(value_[cell] > 0.0)) --cell;  // a u on the last edge
  const int i = static_cast<int>(cell) / kAzimuthCells, j = static_cast<int>(cell) % kAzimuthCells;
  const double cos_zenith = std::clamp(cos_edges_[i] + u1 * (cos_edges_[i + 1] - cos_edges_[i]), -1.0, 1.0);
  const double sin_zenith = std::sqrt(std::max(0.0, 1.0 - cos_zenith * cos_zenith));
  const double phi = kAzimuthWidth * (j + u2);
  return sin_zenith * (std::cos(phi) * frame.toward_sun + std::sin(phi) * frame.across) + cos_zenith * frame.zenith;
}

double DirectionGuide::Pdf(const GuideFrame& frame, const dvec3& direction) const {
  const double cos_zenith = std::clamp(glm::dot(direction, frame.zenith), -1.0, 1.0);
  double phi = std::atan2(glm::dot(direction, frame.across), glm::dot(direction, frame.toward_sun));
  if (phi < 0.0) phi += 2.0 * kPi;
  const int i = ZenithCell(cos_zenith);
  const int j = std::clamp(static_cast<int>(phi / kAzimuthWidth), 0, kAzimuthCells - 1);
  return value_[i * kAzimuthCells + j] / total_;
}

void GuideMixture::Add(const DirectionGuide& guide, double weight) {
  if (!guide.usable() || !(weight > 0.0)) return;
  guides_[count_] = &guide;
  weights_[count_++] = weight;
}

dvec3 GuideMixture::Sample(const GuideFrame& frame, double u_guide, double u_cell, double u1, double u2) const {
  double total = 0.0;
  for (int k = 0; k < count_; ++k) total += weights_[k];
  int k = 0;
  for (double pick = u_guide * total; k + 1 < count_ && pick >= weights_[k]; ++k) pick -= weights_[k];
  return guides_[k]->Sample(frame, u_cell, u1, u2);
}

double GuideMixture::Pdf(const GuideFrame& frame, const dvec3& direction) const {
  double total = 0.0, pdf = 0.0;
  for (int k = 0; k < count_; ++k) {
    total += weights_[k];
    pdf += weights_[k] * guides_[k]->Pdf(frame, direction);
  }
  return pdf / total;
}

double GuideMixture::Incoming() const {
  double total = 0.0, incoming = 0.0;
  for (int k = 0; k < count_; ++k) {
    total += weights_[k];
    incoming += weights_[k] * guides_[k]->Incoming();
  }
  return incoming / total;
}

DirectionGuideField::DirectionGuideField(const LayeredMedium& medium, const SunlightTable& sunlight,
                                         const DirectionGuideField* single, int w)
    : bottom_(medium.bottom_radius()), height_(medium.top_radius() - medium.bottom_radius()) {
  guides_.resize(kAltitudes * kCosines);
  tbb::parallel_for(0, kAltitudes * kCosines, [&](int k) {
    const double x = double(k / kCosines) / (kAltitudes - 1);
    const double mu_s = kMinCosine + (kMaxCosine - kMinCosine) * (k % kCosines) / (kCosines - 1);
    guides_[k] = DirectionGuide(medium, sunlight, single, bottom_ + height_ * x * x, mu_s, w);
  });
}

GuideMixture DirectionGuideField::At(double r, double mu_s) const {
  const double x = std::sqrt(std::clamp((r - bottom_) / height_, 0.0, 1.0)) * (kAltitudes - 1);
  const double y = (std::clamp(mu_s, kMinCosine, kMaxCosine) - kMinCosine) / (kMaxCosine - kMinCosine) * (kCosines - 1);
  const int i = std::min(static_cast<int>(x), kAltitudes - 2), j = std::min(static_cast<int>(y), kCosines - 2);
  const double a = x - i, b = y - j;
  GuideMixture mixture;
  for (int di = 0; di < 2; ++di) {
    for (int dj = 0; dj < 2; ++dj) {
      mixture.Add(guides_[static_cast<std::size_t>(i + di) * kCosines + j + dj],
                  (di ? a : 1.0 - a) * (dj ? b : 1.0 - b));
    }
  }
  return mixture;
}

}  // namespace skybake::reference
