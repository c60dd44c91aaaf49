// Figures about a table's values: per-channel ranges and non-finite counts
// (`skybake info`), and the error that storing them as half floats introduces
// (`skybake bake --half`, `skybake convert --half`).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/table_file.h"

namespace skybake {

struct ChannelStats {
  std::string name;
  double min = 0.0, max = 0.0;  // over finite values; 0 if there are none
  std::size_t finite = 0, nan = 0, inf = 0;
};

std::vector<ChannelStats> ComputeChannelStats(const TableImage& image);

// The smallest normal half, 2^-14. Below it halves are subnormal and their
// relative precision falls off (down to none at 2^-24), so relative error is
// measured only from here up; smaller values are counted and their absolute
// error reported instead.
inline constexpr double kDefaultHalfErrorFloor = 6.103515625e-05;

// Rounding float values to half (Imath::half, round to nearest even):
//   max_relative_error = max |half(v) - v| / |v| over finite v with |v| >= floor
// (at most 2^-11 = 4.88e-4 for values that stay below the half maximum, 65504).
struct HalfError {
  double floor = kDefaultHalfErrorFloor;
  std::size_t measured = 0;      // finite values with |v| >= floor
  double max_relative_error = 0.0;
  double worst_value = 0.0;      // the value where it occurs
  std::size_t below_floor = 0;   // finite non-zero values with |v| < floor
  double max_absolute_error_below_floor = 0.0;
  std::size_t flushed_to_zero = 0;  // non-zero values that became zero
  std::size_t overflowed = 0;       // finite values that became infinite (|v| >= 65520)
};

// Of the `count` values from `values`.
HalfError MeasureHalfError(const float* values, std::size_t count, double floor = kDefaultHalfErrorFloor);

// The same figures with the struct's field names, for --json reports.
nlohmann::json ToJson(const HalfError& error);
nlohmann::json ToJson(const ChannelStats& stats);

}  // namespace skybake
