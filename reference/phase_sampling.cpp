#include "reference/phase_sampling.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/constants.h"

namespace skybake::reference {

double SampleHenyeyGreensteinCosine(double g, double u) {
  // Below |g| = 1e-4 the closed form loses digits to cancellation, and the
  // phase is isotropic to within 3e-4 anyway.
  if (std::abs(g) < 1e-4) return 2.0 * u - 1.0;
  double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
  return std::clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
}

double SampleRayleighCosine(double u) {
  // The CDF (mu^3 + 3 mu + 4) / 8 = u is a depressed cubic with a single
  // real root; Cardano's formula gives it as A - 1 / A.
  double z = 4.0 * u - 2.0;
  double a = std::cbrt(z + std::sqrt(z * z + 1.0));
  return std::clamp(a - 1.0 / a, -1.0, 1.0);
}

double SamplePhaseCosine(const PhaseFunction& phase, Pcg32& rng) {
  switch (phase.kind) {
    case PhaseKind::kIsotropic:
      return 2.0 * rng.Uniform() - 1.0;
    case PhaseKind::kRayleigh:
      return SampleRayleighCosine(rng.Uniform());
    case PhaseKind::kHenyeyGreenstein:
      return SampleHenyeyGreensteinCosine(phase.g, rng.Uniform());
    case PhaseKind::kCornetteShanks:
      // Cornette-Shanks is Henyey-Greenstein times 3 (1 + mu^2) / (2 (2 + g^2)),
      // at most 3 / (2 + g^2): accept a Henyey-Greenstein sample with
      // probability (1 + mu^2) / 2, at least 2 / 3 of the time on average.
      for (;;) {
        double mu = SampleHenyeyGreensteinCosine(phase.g, rng.Uniform());
        if (2.0 * rng.Uniform() < 1.0 + mu * mu) return mu;
      }
  }
  return 2.0 * rng.Uniform() - 1.0;
}

glm::dvec3 DirectionAround(const glm::dvec3& axis, double cos_theta, double u) {
  // Orthonormal basis without a singular axis (Duff et al. 2017).
  double sign = std::copysign(1.0, axis.z);
  double a = -1.0 / (sign + axis.z);
  double b = axis.x * axis.y * a;
  glm::dvec3 t1(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  glm::dvec3 t2(b, sign + axis.y * axis.y * a, -axis.y);
  double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  double phi = 2.0 * kPi * u;
  return glm::normalize(sin_theta * (std::cos(phi) * t1 + std::sin(phi) * t2) + cos_theta * axis);
}

glm::dvec3 SampleCosineHemisphere(const glm::dvec3& normal, double u1, double u2) {
  // Malley's method: uniform on the disc, projected up to the hemisphere.
  return DirectionAround(normal, std::sqrt(1.0 - u1), u2);
}

}  // namespace skybake::reference
