#include "fit/forms.h"

#include <algorithm>

namespace skybake::fit {

const char* ToString(FormKind kind) {
  switch (kind) {
    case FormKind::kChapmanChord: return "chapman-chord";
    case FormKind::kKasten: return "kasten";
  }
  return "unknown";
}

bool ParseFormKind(const std::string& name, FormKind* kind) {
  for (FormKind k : {FormKind::kChapmanChord, FormKind::kKasten}) {
    if (name == ToString(k)) {
      *kind = k;
      return true;
    }
  }
  return false;
}

std::array<const char*, kShapeParameters> ParameterNames(FormKind kind) {
  if (kind == FormKind::kChapmanChord) return {"ln_epsilon", "ln_a", "ln_b"};
  return {"ln_a", "ln_b_minus_90", "ln_c"};
}

ParameterBounds Bounds(FormKind kind, int parameter) {
  // ε spans 1e-13 (a thin layer's last metres on a large planet) to 1e13
  // (an atmosphere far thicker than its planet's radius); the other
  // parameters are O(1) for every profile seen, the bounds only keep a
  // degenerate fit finite.
  // Kasten's (b - θ°)^-c is kept below ~1e14 at the horizon.
  // τ - 1 from 1e-6 (a layer ending a millionth of the range above it) to
  // 3000 (no layer top in sight: the factor is then constant to 1e-3).
  if (parameter == kShapeParameters) return {-14.0, 8.0};
  if (kind == FormKind::kChapmanChord) return parameter == 0 ? ParameterBounds{-30.0, 30.0}
                                                             : ParameterBounds{-12.0, 12.0};
  if (parameter == 1) return {-4.0, 6.0};
  if (parameter == 2) return {-4.0, 1.5};
  return {-12.0, 12.0};
}

double IqbalRelativeOpticalPath(double mu) {
  constexpr double kDegreesPerRadian = 57.295779513082320876798;
  double theta_deg = std::acos(std::clamp(mu, 0.0, 1.0)) * kDegreesPerRadian;
  return 1.0 / (mu + 0.15 * std::pow(93.885 - theta_deg, -1.253));
}

}  // namespace skybake::fit
