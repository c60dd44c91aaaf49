#include "reference/sunlight_table.h"

#include <algorithm>
#include <cmath>

#include "reference/ray_segment.h"
#include "shaders_runtime/runtime.h"

namespace skybake::reference {

namespace {
// The guide needs the shape of the sunlight, not its last digits.
constexpr double kGuideTolerance = 1e-3;
}  // namespace

SunlightTable::SunlightTable(const LayeredMedium& medium)
    : bottom_(medium.bottom_radius()), height_(medium.top_radius() - medium.bottom_radius()) {
  const glsl::AtmosphereParameters& g = medium.geometry();
  values_.resize(std::size_t(kRadii) * kCosines);
  for (int i = 0; i < kRadii; ++i) {
    const double x = double(i) / (kRadii - 1), r = bottom_ + height_ * x * x;
    for (int j = 0; j < kCosines; ++j) {
      const double mu_s = -1.0 + 2.0 * j / (kCosines - 1);
      const double visible = glsl::SunVisibleFraction(g, r, mu_s);
      Spectrum sunlight(0.0);
      if (visible > 0.0) {
        const double mu = SunRayCosine(g, r, mu_s);
        const double length = glsl::DistanceToTopAtmosphereBoundary(g, r, mu);
        sunlight = visible * glm::exp(-medium.OpticalDepth(r, mu, 0.0, length, kGuideTolerance).value);
      }
      values_[std::size_t(i) * kCosines + j] = sunlight;
    }
  }
}

Spectrum SunlightTable::At(double r, double mu_s) const {
  const double x = std::sqrt(std::clamp((r - bottom_) / height_, 0.0, 1.0)) * (kRadii - 1);
  const double y = std::clamp((mu_s + 1.0) * 0.5, 0.0, 1.0) * (kCosines - 1);
  const int i = std::min(static_cast<int>(x), kRadii - 2), j = std::min(static_cast<int>(y), kCosines - 2);
  const double fx = x - i, fy = y - j;
  auto value = [&](int a, int b) { return values_[std::size_t(a) * kCosines + b]; };
  return (1.0 - fx) * ((1.0 - fy) * value(i, j) + fy * value(i, j + 1)) +
         fx * ((1.0 - fy) * value(i + 1, j) + fy * value(i + 1, j + 1));
}

}  // namespace skybake::reference
