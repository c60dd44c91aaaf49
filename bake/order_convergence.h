// The convergence of the scattering orders and the geometric tail of the
// orders not computed.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "core/spectrum.h"

namespace skybake::detail {

// Sums over the scattering table, per channel, of the accumulated table and
// of the newest order, both divided by the Rayleigh phase as the table is.
struct OrderSums {
  Spectrum table{0.0}, newest{0.0};
};

// Order-by-order convergence of the scattering orders. Past the first few
// orders each order is close to the previous one times a constant ratio q
// (the dominant eigenvalue of the scattering operator), so the orders not
// computed sum to newest * q / (1 - q). Ratios and sizes are per channel and
// global over the table: per texel ratios are noisy where orders are tiny.
class OrderConvergence {
 public:
  void Add(const OrderSums& sums) {
    previous_ratio_ = ratio_;
    ratio_ = has_newest_ ? Divide(sums.newest, newest_) : Spectrum(-1.0);
    has_previous_ratio_ = has_ratio_;
    has_ratio_ = has_newest_;
    newest_ = sums.newest;
    has_newest_ = true;
    relative_ = Divide(sums.newest, sums.table);
  }
  bool NewestIsZero() const { return Max(newest_) <= 0.0; }
  // Largest ratio over the channels (0 before the third order).
  double Ratio() const { return has_ratio_ ? std::max(0.0, Max(ratio_)) : 0.0; }
  // Estimate of the orders not computed, relative to the table: the
  // geometric tail if the ratio is known and below 1, otherwise the newest
  // order alone (a lower bound).
  double RemainingWithoutTail() const {
    double remaining = 0.0;
    for (int c = 0; c < 3; ++c) {
      bool geometric = has_ratio_ && ratio_[c] >= 0.0 && ratio_[c] < kMaxRatio;
      remaining = std::max(remaining, geometric ? relative_[c] * ratio_[c] / (1.0 - ratio_[c]) : relative_[c]);
    }
    return remaining;
  }
  // q / (1 - q) per channel once the ratio is known twice and below
  // kMaxRatio (a ratio near or above 1 means the series is not yet geometric).
  std::optional<Spectrum> TailFactor() const {
    if (!has_previous_ratio_) return std::nullopt;
    Spectrum factor(0.0);
    for (int c = 0; c < 3; ++c) {
      if (relative_[c] <= 0.0) continue;
      if (ratio_[c] < 0.0 || ratio_[c] >= kMaxRatio || previous_ratio_[c] < 0.0) return std::nullopt;
      factor[c] = ratio_[c] / (1.0 - ratio_[c]);
    }
    return factor;
  }
  double RelativeTail() const {
    std::optional<Spectrum> factor = TailFactor();
    return factor ? Max(relative_ * *factor) : 0.0;
  }
  // Error of the extrapolated tail: its derivative newest / (1 - q)^2 with
  // respect to q times the change of q over the last order.
  double TailError() const {
    if (!TailFactor()) return std::numeric_limits<double>::infinity();
    double error = 0.0;
    for (int c = 0; c < 3; ++c) {
      if (relative_[c] <= 0.0) continue;
      double one_minus_q = 1.0 - ratio_[c];
      error = std::max(error, relative_[c] * std::abs(ratio_[c] - previous_ratio_[c]) / (one_minus_q * one_minus_q));
    }
    return error;
  }

 private:
  static constexpr double kMaxRatio = 0.999;
  // a / b per channel; 0 where b is 0 (nothing to compare against).
  static Spectrum Divide(const Spectrum& a, const Spectrum& b) {
    Spectrum q(0.0);
    for (int c = 0; c < 3; ++c) q[c] = b[c] > 0.0 ? a[c] / b[c] : 0.0;
    return q;
  }
  static double Max(const Spectrum& v) { return std::max({v.x, v.y, v.z}); }

  bool has_newest_ = false, has_ratio_ = false, has_previous_ratio_ = false;
  Spectrum newest_{0.0}, relative_{0.0}, ratio_{0.0}, previous_ratio_{0.0};
};
}  // namespace skybake::detail
