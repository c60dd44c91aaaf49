// Atmospheres built in code from DESIGN.md's published values, so tests of
// the physics do not depend on the TOML reader (which has its own tests).
#pragma once

#include <cmath>

#include "bake/atmosphere.h"
#include "bake/bake.h"
#include "bake/stress_set.h"
#include "core/constants.h"

namespace skybake::testing {

inline Constituent ExponentialConstituent(const char* name, Spectrum scattering, Spectrum absorption,
                                          double scale_height_m, PhaseFunction phase) {
  Constituent c;
  c.name = name;
  c.scattering_per_m = scattering;
  c.absorption_per_m = absorption;
  c.phase = phase;
  c.density.layers = {DensityLayer{0.0, 1.0, -1.0 / scale_height_m, 0.0, 0.0}};
  return c;
}

// Bruneton 2017's Earth (DESIGN.md "earth").
inline Atmosphere Earth() {
  Atmosphere a;
  a.name = "earth";
  a.bottom_radius_m = 6360e3;
  a.top_radius_m = 6420e3;
  a.ground_albedo = Spectrum(0.1);
  a.wavelengths_nm = Spectrum(680.0, 550.0, 440.0);
  a.solar_irradiance = Spectrum(1.474, 1.8504, 1.91198);
  a.sun_angular_radius_rad = 0.004675;
  a.mu_s_min = std::cos(102.0 * kPi / 180.0);
  Constituent ozone;
  ozone.name = "ozone";
  ozone.absorption_per_m = Spectrum(0.650e-6, 1.881e-6, 0.085e-6);
  ozone.density.layers = {DensityLayer{25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0},
                          DensityLayer{0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0}};
  a.constituents = {
      ExponentialConstituent("rayleigh", Spectrum(5.802e-6, 13.558e-6, 33.100e-6), Spectrum(0.0), 8000.0,
                             PhaseFunction{PhaseKind::kRayleigh, 0.0}),
      ExponentialConstituent("mie", Spectrum(3.996e-6), Spectrum(0.444e-6), 1200.0,
                             PhaseFunction{PhaseKind::kCornetteShanks, 0.8}),
      ozone};
  return a;
}

// Small tables and sample counts (a bake in well under a second) for tests
// that compare two evaluations of the same tables, where size does not matter.
// The stress set's small tables, at two orders.
inline BakeSettings SmallBakeSettings() {
  BakeSettings s = StressBakeSettings();
  s.orders = 2;
  return s;
}

// Earth's single scattering at the default table sizes (one order, no
// tail), baked once per test binary.
inline const LutSet& DefaultSizeEarthSingleScattering() {
  static const LutSet luts = [] {
    BakeSettings settings;
    settings.orders = 1;
    settings.extrapolate_tail = false;
    return Bake(Earth(), settings);
  }();
  return luts;
}

}  // namespace skybake::testing
