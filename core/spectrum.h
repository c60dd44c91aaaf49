// A quantity given per wavelength.
#pragma once

#include <glm/vec3.hpp>

namespace skybake {

// One value per wavelength. Tables carry one wavelength per RGB channel, so an
// atmosphere has exactly three wavelengths.
using Spectrum = glm::dvec3;
constexpr int kWavelengthCount = 3;

}  // namespace skybake
