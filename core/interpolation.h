// Piecewise-linear interpolation of tabulated samples, the one form every
// table of an atmosphere file and every published spectrum is read with.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace skybake {

// The value at `x` of the function linear between the samples (xs[i], ys[i])
// (xs increasing, at least one sample), held at its end values outside them.
inline double PiecewiseLinear(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  if (x <= xs.front()) return ys.front();
  if (x >= xs.back()) return ys.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
  const double t = (x - xs[i - 1]) / (xs[i] - xs[i - 1]);
  return ys[i - 1] + t * (ys[i] - ys[i - 1]);
}

}  // namespace skybake
