#include "bake/physics.h"
#include "core/constants.h"

#include <cmath>

namespace skybake {

namespace {
}

double KingFactor(double depolarization) {
  return (6.0 + 3.0 * depolarization) / (6.0 - 7.0 * depolarization);
}

double RayleighScatteringCoefficient(double refractive_index, double number_density_per_m3,
                                     double depolarization, double wavelength_m) {
  // (n^2 - 1) is ~6e-4 for air: form it as (n - 1)(n + 1) so the small
  // difference is not taken between two numbers close to 1 after squaring.
  double n2_minus_1 = (refractive_index - 1.0) * (refractive_index + 1.0);
  double lambda2 = wavelength_m * wavelength_m;
  return 8.0 * kPi * kPi * kPi * n2_minus_1 * n2_minus_1 /
         (3.0 * number_density_per_m3 * lambda2 * lambda2) * KingFactor(depolarization);
}

double RayleighLawCoefficient(double at_1um_per_m, double wavelength_nm) {
  double lambda_um = wavelength_nm / 1000.0;
  double lambda2 = lambda_um * lambda_um;
  return at_1um_per_m / (lambda2 * lambda2);
}

double AngstromCoefficient(double reference_per_m, double reference_nm, double exponent,
                           double wavelength_nm) {
  return reference_per_m * std::pow(wavelength_nm / reference_nm, -exponent);
}

}  // namespace skybake
