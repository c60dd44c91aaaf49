#include "formats/table_stats.h"

#include <algorithm>
#include <cmath>

#include <Imath/half.h>

namespace skybake {

std::vector<ChannelStats> ComputeChannelStats(const TableImage& image) {
  const std::size_t channels = image.channel_names.size();
  std::vector<ChannelStats> stats(channels);
  for (std::size_t c = 0; c < channels; ++c) {
    ChannelStats& s = stats[c];
    s.name = image.channel_names[c];
    double low = INFINITY, high = -INFINITY;
    for (std::size_t i = c; i < image.values.size(); i += channels) {
      const float v = image.values[i];
      if (std::isnan(v)) {
        ++s.nan;
      } else if (std::isinf(v)) {
        ++s.inf;
      } else {
        ++s.finite;
        low = std::min<double>(low, v);
        high = std::max<double>(high, v);
      }
    }
    if (s.finite > 0) s.min = low, s.max = high;
  }
  return stats;
}

HalfError MeasureHalfError(const float* values, std::size_t count, double floor) {
  HalfError e;
  e.floor = floor;
  for (std::size_t i = 0; i < count; ++i) {
    const float v = values[i];
    if (!std::isfinite(v)) continue;
    const float h = static_cast<float>(Imath::half(v));
    if (std::isinf(h)) {
      ++e.overflowed;
      continue;
    }
    if (v != 0.0f && h == 0.0f) ++e.flushed_to_zero;
    const double error = std::fabs(static_cast<double>(h) - v);
    const double magnitude = std::fabs(static_cast<double>(v));
    if (magnitude >= floor) {
      ++e.measured;
      const double relative = error / magnitude;
      if (relative > e.max_relative_error) e.max_relative_error = relative, e.worst_value = v;
    } else if (v != 0.0f) {
      ++e.below_floor;
      e.max_absolute_error_below_floor = std::max(e.max_absolute_error_below_floor, error);
    }
  }
  return e;
}

nlohmann::json ToJson(const HalfError& e) {
  return nlohmann::json{{"floor", e.floor},
                        {"measured", e.measured},
                        {"max_relative_error", e.max_relative_error},
                        {"worst_value", e.worst_value},
                        {"below_floor", e.below_floor},
                        {"max_absolute_error_below_floor", e.max_absolute_error_below_floor},
                        {"flushed_to_zero", e.flushed_to_zero},
                        {"overflowed", e.overflowed}};
}

nlohmann::json ToJson(const ChannelStats& s) {
  return nlohmann::json{{"name", s.name}, {"min", s.min},   {"max", s.max},
                        {"finite", s.finite}, {"nan", s.nan}, {"inf", s.inf}};
}

}  // namespace skybake
