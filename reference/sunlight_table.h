// Sunlight at a point, tabulated over (radius, sun zenith cosine) once per
// atmosphere: the visible fraction of the sun's disc times the transmittance
// toward it. Only a guide for where paths look for sunlit scattering (the
// density they sample distances from); every estimate still uses the exact
// sunlight (Tracer::Sunlight), so the table's resolution costs variance,
// never bias.
#pragma once

#include <vector>

#include "bake/atmosphere.h"
#include "reference/layered_medium.h"

namespace skybake::reference {

class SunlightTable {
 public:
  explicit SunlightTable(const LayeredMedium& medium);

  // Visible fraction x transmittance to the sun at radius r for the sun's
  // zenith cosine mu_s, per wavelength (bilinear in the table).
  Spectrum At(double r, double mu_s) const;

 private:
  // Radii at altitudes top_height (i / (kRadii - 1))^2 (dense near the
  // ground, where the transmittance toward a low sun falls fastest), sun
  // cosines uniform in [-1, 1].
  static constexpr int kRadii = 32, kCosines = 512;
  double bottom_ = 0.0, height_ = 0.0;
  std::vector<Spectrum> values_;  // kCosines per radius
};

}  // namespace skybake::reference
