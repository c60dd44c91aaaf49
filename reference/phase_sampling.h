// Sampling of scattering directions: each phase function of the atmosphere
// model exactly (inverse CDF for Henyey-Greenstein and Rayleigh, rejection
// from Henyey-Greenstein for Cornette-Shanks), and cosine-weighted
// hemispheres for the Lambertian ground and for irradiance.
#pragma once

#include <glm/vec3.hpp>

#include "bake/atmosphere.h"
#include "reference/random.h"

namespace skybake::reference {

// Cosine of the scattering angle with density 2 pi phase.Evaluate(cos) on
// [-1, 1]; the direction's azimuth is uniform and drawn separately.
double SamplePhaseCosine(const PhaseFunction& phase, Pcg32& rng);

// Inverse CDFs of the phases that have one, for u in [0, 1).
double SampleHenyeyGreensteinCosine(double g, double u);
double SampleRayleighCosine(double u);

// The unit vector at angle acos(cos_theta) from the unit vector `axis`, at
// azimuth 2 pi u around it.
glm::dvec3 DirectionAround(const glm::dvec3& axis, double cos_theta, double u);

// A direction with density cos(theta) / pi about the unit `normal`.
glm::dvec3 SampleCosineHemisphere(const glm::dvec3& normal, double u1, double u2);

}  // namespace skybake::reference
