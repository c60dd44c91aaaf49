// Density profiles, atmospheres built in code and small helpers shared by
// the tests of the sky-dome fit (fit_test.cpp, fit_quadrature_test.cpp,
// fit_codegen_test.cpp).
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "bake/atmosphere.h"
#include "core/constants.h"

namespace skybake::fit {

inline constexpr double kEarthRadius = 6360e3;
inline constexpr double kEarthTop = 6420e3;

// ---- density profiles ----

inline DensityProfile Exponential(double scale_height_m) {
  DensityProfile p;
  p.layers.push_back({0.0, 1.0, -1.0 / scale_height_m, 0.0, 0.0});
  return p;
}

inline DensityProfile Constant(double density) {
  DensityProfile p;
  p.layers.push_back({0.0, 0.0, 0.0, 0.0, density});
  return p;
}

inline DensityProfile Slab(double thickness_m) {
  DensityProfile p;
  p.layers.push_back({thickness_m, 0.0, 0.0, 0.0, 1.0});
  p.layers.push_back({0.0, 0.0, 0.0, 0.0, 0.0});
  return p;
}

// 0 below 10 km, rising linearly to 1 at 25 km, back to 0 at 40 km.
inline DensityProfile OzoneTent() {
  DensityProfile p;
  p.layers.push_back({25000.0, 0.0, 0.0, 1.0 / 15000.0, -2.0 / 3.0});
  p.layers.push_back({0.0, 0.0, 0.0, -1.0 / 15000.0, 8.0 / 3.0});
  return p;
}

inline double Mu(double zenith_deg) { return zenith_deg >= 90.0 ? 0.0 : std::cos(zenith_deg * kPi / 180.0); }

// ---- atmospheres built in code (DESIGN.md values) ----

inline Constituent MakeConstituent(const std::string& name, DensityProfile density, Spectrum scattering,
                            Spectrum absorption, PhaseKind phase, double g = 0.0) {
  Constituent c;
  c.name = name;
  c.density = std::move(density);
  c.scattering_per_m = scattering;
  c.absorption_per_m = absorption;
  c.phase = {phase, g};
  return c;
}

inline Atmosphere Planet(const std::string& name, double bottom, double top) {
  Atmosphere a;
  a.name = name;
  a.bottom_radius_m = bottom;
  a.top_radius_m = top;
  return a;
}

inline Constituent Rayleigh(double scale_height_m = 8000.0) {
  return MakeConstituent("rayleigh", Exponential(scale_height_m), {5.802e-6, 13.558e-6, 33.100e-6}, Spectrum(0.0),
                         PhaseKind::kRayleigh);
}

inline Atmosphere Earth() {
  Atmosphere a = Planet("earth", kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(),
                    MakeConstituent("mie", Exponential(1200.0), Spectrum(3.996e-6), Spectrum(0.444e-6),
                                    PhaseKind::kCornetteShanks, 0.8),
                    MakeConstituent("ozone", OzoneTent(), Spectrum(0.0), {0.650e-6, 1.881e-6, 0.085e-6},
                                    PhaseKind::kIsotropic)};
  return a;
}

inline Atmosphere EarthClear2008() {
  Atmosphere a = Planet("earth-clear-2008", kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(), MakeConstituent("mie", Exponential(1200.0), Spectrum(2e-5), Spectrum(2e-5 / 0.9 - 2e-5),
                                                PhaseKind::kCornetteShanks, 0.76)};
  return a;
}

// Hoffman & Preetham's haze table. How the config branch will shape the haze
// is not settled, so both a 1.25 km constant-density slab (their constant
// haze with its 1.25 km zenith optical length) and an exponential with a
// 1.25 km scale height are covered.
inline Atmosphere Haze(const std::string& name, Spectrum scattering, bool slab) {
  Atmosphere a = Planet(name + (slab ? "" : "-exponential"), kEarthRadius, kEarthTop);
  a.constituents = {Rayleigh(), MakeConstituent("haze", slab ? Slab(1250.0) : Exponential(1250.0), scattering,
                                                Spectrum(0.0), PhaseKind::kHenyeyGreenstein, 0.8)};
  return a;
}

inline Atmosphere Mars() {
  Atmosphere a = Planet("mars", 3389.5e3, 3389.5e3 + 80e3);
  a.constituents = {MakeConstituent("co2", Exponential(11000.0), {19.918e-6, 13.57e-6, 5.75e-6}, Spectrum(0.0),
                                    PhaseKind::kRayleigh),
                    MakeConstituent("dust", Exponential(3100.0), Spectrum(53.6e-6), Spectrum(53.6e-6 / 0.99 - 53.6e-6),
                                    PhaseKind::kHenyeyGreenstein, 0.85)};
  return a;
}

inline std::vector<Atmosphere> Presets() {
  std::vector<Atmosphere> presets = {Earth(), EarthClear2008(), Mars()};
  for (bool slab : {true, false}) {
    presets.push_back(Haze("light-haze", {2e-5, 3e-5, 4e-5}, slab));
    presets.push_back(Haze("heavy-haze", {8e-5, 1e-4, 1.2e-4}, slab));
    presets.push_back(Haze("light-fog", {9e-4, 1e-3, 1.1e-3}, slab));
    presets.push_back(Haze("heavy-fog", {1e-2, 1e-2, 1e-2}, slab));
  }
  return presets;
}

inline Atmosphere SingleExponential(double scale_height_m, double top = kEarthTop) {
  Atmosphere a = Planet("exponential", kEarthRadius, top);
  a.constituents = {MakeConstituent("air", Exponential(scale_height_m), Spectrum(1e-5), Spectrum(0.0),
                                    PhaseKind::kRayleigh)};
  return a;
}

}  // namespace skybake::fit
