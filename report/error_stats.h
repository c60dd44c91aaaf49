// Error statistics of `skybake report`: relative errors of computed values
// against the reference, over the cases of one group, with the reference's
// own noise kept apart from the error it measures.
//
// One sample is one channel (or the luminance) of one case. A sample whose
// difference from the reference is smaller than kNoiseStandardErrors of the
// reference's standard errors is "below noise": the reference cannot tell it
// from zero. A group's RMS is below noise when it does not exceed the RMS of
// those noise bounds (relative), its max when every sample is below noise;
// both are then reported as such, not as the (noise-dominated) number.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace skybake::report {

// Differences under two standard errors are what a perfect model would show
// in about 95% of the samples of a Gaussian reference.
inline constexpr double kNoiseStandardErrors = 2.0;

// Rec. 709 luminance weights, applied to the three channels as a renderer
// displays them (red, green, blue).
inline constexpr double kLuminanceWeights[3] = {0.2126, 0.7152, 0.0722};

inline double Luminance(const glm::dvec3& rgb) {
  return kLuminanceWeights[0] * rgb.x + kLuminanceWeights[1] * rgb.y + kLuminanceWeights[2] * rgb.z;
}
// The standard error of the luminance of independent channel estimates.
double LuminanceStandardError(const glm::dvec3& standard_error);

struct ErrorSample {
  double value = 0.0;
  double reference = 0.0;
  double standard_error = 0.0;  // of the reference; 0 for exact references
};

struct ErrorStats {
  int count = 0;        // samples measured: reference > 0 and finite
  int skipped = 0;      // samples left out: reference <= 0 (e.g. no sunlight) or not finite
  int below_noise = 0;  // measured samples with |value - reference| < kNoiseStandardErrors * standard error
  double mean_relative = 0.0;  // mean(|value - reference| / reference); inf if a value is not finite
  double rms_relative = 0.0;  // sqrt(mean(((value - reference) / reference)^2)); inf if a value is not finite
  double max_relative = 0.0;
  double rms_noise = 0.0;     // sqrt(mean((kNoiseStandardErrors * standard_error / reference)^2))

  bool RmsBelowNoise() const { return count > 0 && rms_relative <= rms_noise; }
  bool MaxBelowNoise() const { return count > 0 && below_noise == count; }
};

ErrorStats ComputeErrorStats(const std::vector<ErrorSample>& samples);

// "1.23%", "below noise (< 0.40%)", or "n/a" when nothing was measured.
std::string FormatRms(const ErrorStats& stats);
std::string FormatMax(const ErrorStats& stats);

// For points (cost, error): true for those no other point beats, i.e. none
// has cost <= and error <= with one of them strictly smaller. Points with a
// non-finite or negative coordinate are never on the front.
std::vector<bool> ParetoFront(const std::vector<double>& cost, const std::vector<double>& error);

}  // namespace skybake::report
