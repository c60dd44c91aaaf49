#include "core/phase.h"

#include <cmath>

#include "core/constants.h"

namespace skybake {

double IsotropicPhase() { return 1.0 / (4.0 * kPi); }

double RayleighPhase(double mu) { return 3.0 / (16.0 * kPi) * (1.0 + mu * mu); }

double HenyeyGreensteinPhase(double g, double mu) {
  double denom = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPi * denom * std::sqrt(denom));
}

double CornetteShanksPhase(double g, double mu) {
  double denom = 1.0 + g * g - 2.0 * g * mu;
  double k = 3.0 / (8.0 * kPi) * (1.0 - g * g) / (2.0 + g * g);
  return k * (1.0 + mu * mu) / (denom * std::sqrt(denom));
}

}  // namespace skybake
