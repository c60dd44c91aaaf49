#include "report/error_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/errors.h"

namespace skybake::report {

double LuminanceStandardError(const glm::dvec3& e) {
  double variance = 0.0;
  for (int c = 0; c < 3; ++c) variance += kLuminanceWeights[c] * kLuminanceWeights[c] * e[c] * e[c];
  return std::sqrt(variance);
}

ErrorStats ComputeErrorStats(const std::vector<ErrorSample>& samples) {
  ErrorStats s;
  double sum = 0.0, sum_squares = 0.0, noise_squares = 0.0;
  for (const ErrorSample& sample : samples) {
    if (!(std::isfinite(sample.reference) && sample.reference > 0.0)) {
      ++s.skipped;
      continue;
    }
    ++s.count;
    double difference = std::abs(sample.value - sample.reference);
    double relative = std::isfinite(sample.value) ? difference / sample.reference : INFINITY;
    double noise = kNoiseStandardErrors * sample.standard_error;
    if (difference < noise) ++s.below_noise;
    sum += relative;
    sum_squares += relative * relative;
    noise_squares += (noise / sample.reference) * (noise / sample.reference);
    s.max_relative = std::max(s.max_relative, relative);
  }
  if (s.count > 0) {
    s.mean_relative = sum / s.count;
    s.rms_relative = std::sqrt(sum_squares / s.count);
    s.rms_noise = std::sqrt(noise_squares / s.count);
  }
  return s;
}

namespace {

std::string Percent(double fraction) {
  if (!std::isfinite(fraction)) return "inf";
  char text[32];
  std::snprintf(text, sizeof text, fraction < 0.001 ? "%.3f%%" : "%.2f%%", 100.0 * fraction);
  return text;
}

}  // namespace

std::string FormatRms(const ErrorStats& s) {
  if (s.count == 0) return "n/a";
  if (s.RmsBelowNoise()) return "below noise (< " + Percent(s.rms_noise) + ")";
  return Percent(s.rms_relative);
}

std::string FormatMax(const ErrorStats& s) {
  if (s.count == 0) return "n/a";
  if (s.MaxBelowNoise()) return "below noise";
  return Percent(s.max_relative);
}

std::vector<bool> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error) {
  if (cost.size() != error.size()) throw InternalError("ParetoFront: cost and error differ in length");
  auto valid = [&](size_t i) {
    return std::isfinite(cost[i]) && std::isfinite(error[i]) && cost[i] >= 0.0 && error[i] >= 0.0;
  };
  std::vector<bool> front(cost.size(), false);
  for (size_t i = 0; i < cost.size(); ++i) {
    if (!valid(i)) continue;
    bool dominated = false;
    for (size_t j = 0; j < cost.size() && !dominated; ++j) {
      if (j == i || !valid(j)) continue;
      dominated = cost[j] <= cost[i] && error[j] <= error[i] && (cost[j] < cost[i] || error[j] < error[i]);
    }
    front[i] = !dominated;
  }
  return front;
}

}  // namespace skybake::report
