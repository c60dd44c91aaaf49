#include "bake/stress_set.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "bake/config.h"
#include "core/constants.h"

namespace skybake {

namespace {

constexpr double kEarthRadius = 6360e3;

// Earth's sun, wavelengths and lowest sun (DESIGN.md "earth") around a planet
// of the given radii.
Atmosphere Planet(const char* name, const char* stresses, double bottom_radius_m, double top_radius_m) {
  Atmosphere a;
  a.name = name;
  a.description = stresses;
  a.bottom_radius_m = bottom_radius_m;
  a.top_radius_m = top_radius_m;
  a.ground_albedo = Spectrum(0.1);
  a.wavelengths_nm = Spectrum(680.0, 550.0, 440.0);
  a.solar_irradiance = Spectrum(1.474, 1.8504, 1.91198);
  a.sun_angular_radius_rad = 0.004675;
  a.mu_s_min = std::cos(102.0 * kPi / 180.0);
  return a;
}

Constituent WithDensity(const char* name, Spectrum scattering, Spectrum absorption, PhaseFunction phase,
                        std::vector<DensityLayer> layers) {
  Constituent c;
  c.name = name;
  c.scattering_per_m = scattering;
  c.absorption_per_m = absorption;
  c.phase = phase;
  c.density.layers = std::move(layers);
  return c;
}

Constituent Uniform(const char* name, Spectrum scattering, Spectrum absorption, PhaseFunction phase) {
  return WithDensity(name, scattering, absorption, phase, {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}});
}

Constituent Exponential(const char* name, Spectrum scattering, Spectrum absorption, double scale_height_m,
                        PhaseFunction phase) {
  return WithDensity(name, scattering, absorption, phase, {DensityLayer{0.0, 1.0, -1.0 / scale_height_m, 0.0, 0.0}});
}

// A medium of extinction `extinction` and single-scattering albedo `albedo`.
Constituent Haze(const char* name, Spectrum extinction, double albedo, PhaseFunction phase,
                 std::vector<DensityLayer> layers) {
  return WithDensity(name, extinction * albedo, extinction * (1.0 - albedo), phase, std::move(layers));
}

const PhaseFunction kRayleigh{PhaseKind::kRayleigh, 0.0};
const PhaseFunction kIsotropic{PhaseKind::kIsotropic, 0.0};
// Relative spectrum of the stiff media: the stated optical depth is reached
// in the 440 nm (blue) channel, a quarter and a half of it in the others.
const Spectrum kBlueHeavy(0.25, 0.5, 1.0);

// Earth's air (DESIGN.md), optical depth 0.04 / 0.09 / 0.26 at the zenith.
Constituent EarthAir() {
  return Exponential("rayleigh", Spectrum(5.802e-6, 13.558e-6, 33.100e-6), Spectrum(0.0), 8000.0, kRayleigh);
}

}  // namespace

std::vector<StressAtmosphere> StressSet() {
  std::vector<StressAtmosphere> set;
  auto add = [&](Atmosphere a, bool must_balance_energy = false) {
    Validate(a, a.name);
    set.push_back(StressAtmosphere{std::move(a), must_balance_energy});
  };
  const std::vector<DensityLayer> kConstant = {DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}};

  {  // Vertical optical depth 10 (blue) in a 10 km slab: extinction 1e-3 m^-1.
    Atmosphere a = Planet("optical-depth-10", "vertical optical depth 10, albedo 0.99, HG g = 0.7 slab",
                          kEarthRadius, kEarthRadius + 10e3);
    a.constituents = {Haze("haze", kBlueHeavy * 1e-3, 0.99, {PhaseKind::kHenyeyGreenstein, 0.7}, kConstant)};
    add(a);
  }
  {  // Exponential, 2 km scale height: tau = 0.05 m^-1 * 2 km * (1 - e^-10) = 100.
    Atmosphere a = Planet("optical-depth-100", "vertical optical depth 100, albedo 0.9, Rayleigh phase",
                          kEarthRadius, kEarthRadius + 20e3);
    a.constituents = {Haze("haze", kBlueHeavy * 0.05, 0.9, kRayleigh, {DensityLayer{0.0, 1.0, -1.0 / 2000.0, 0.0, 0.0}})};
    add(a);
  }
  {  // 10 km slab of extinction 0.1 m^-1.
    Atmosphere a = Planet("optical-depth-1000", "vertical optical depth 1000, albedo 0.8, isotropic slab",
                          kEarthRadius, kEarthRadius + 10e3);
    a.constituents = {Haze("haze", kBlueHeavy * 0.1, 0.8, kIsotropic, kConstant)};
    add(a);
  }
  {  // Optical depth 1 (blue), absorption one millionth of the extinction.
    Atmosphere a = Planet("albedo-0.999999", "single-scattering albedo 0.999999, optical depth 1, ground 0.3",
                          kEarthRadius, kEarthRadius + 60e3);
    Spectrum scattering = kBlueHeavy * 1.25e-4;
    a.constituents = {Exponential("air", scattering, scattering * 1e-6, 8000.0, kRayleigh)};
    a.ground_albedo = Spectrum(0.3);
    add(a);
  }
  for (double g : {0.999, -0.999}) {
    Atmosphere a = Planet(g > 0 ? "forward-g-0.999" : "backward-g-0.999",
                          g > 0 ? "Earth air and a Henyey-Greenstein haze with g = +0.999"
                                : "Earth air and a Henyey-Greenstein haze with g = -0.999",
                          kEarthRadius, kEarthRadius + 60e3);
    a.constituents = {EarthAir(),
                      Exponential("haze", Spectrum(2e-5), Spectrum(0.0), 1200.0, {PhaseKind::kHenyeyGreenstein, g})};
    add(a);
  }
  {  // 1 km planet, 500 m of air: optical depth 0.5 at the zenith.
    Atmosphere a = Planet("tiny-planet-1km", "planet radius 1 km, 500 m of uniform air, ground 0.3", 1e3, 1.5e3);
    a.constituents = {Uniform("air", kBlueHeavy * 1e-3, Spectrum(0.0), kRayleigh)};
    a.ground_albedo = Spectrum(0.3);
    add(a);
  }
  {  // 100,000 km planet, 20 km scale height: optical depth 0.5.
    Atmosphere a = Planet("giant-planet-100000km", "planet radius 100,000 km, 200 km of exponential air", 1e8,
                          1e8 + 200e3);
    a.constituents = {Exponential("air", kBlueHeavy * 2.5e-5, Spectrum(0.0), 20e3, kRayleigh)};
    add(a);
  }
  {  // 1 m of air, extinction 0.1 m^-1: 0.1 at the zenith, ~360 along the horizon.
    Atmosphere a = Planet("thin-shell-1m", "atmosphere 1 m thick on an Earth-sized planet, optical depth 0.1",
                          kEarthRadius, kEarthRadius + 1.0);
    a.constituents = {Uniform("air", kBlueHeavy * 0.1, Spectrum(0.0), kRayleigh)};
    add(a);
  }
  {  // 100 km planet, atmosphere 10 radii thick, 100 km scale height: 0.5.
    Atmosphere a = Planet("thick-shell-10R", "atmosphere 10 planet radii thick (100 km planet)", 100e3, 1100e3);
    a.constituents = {Exponential("air", kBlueHeavy * 5e-6, Spectrum(0.0), 100e3, kRayleigh)};
    add(a);
  }
  {  // Haze in 0-2 km and 20-60 km, nothing in between.
    Atmosphere a = Planet("vacuum-gap", "haze layers at 0-2 km and 20-60 km with vacuum between",
                          kEarthRadius, kEarthRadius + 60e3);
    a.constituents = {Haze("haze", Spectrum(2e-5), 1.0, {PhaseKind::kHenyeyGreenstein, 0.8},
                           {DensityLayer{2000.0, 0.0, 0.0, 0.0, 1.0}, DensityLayer{18000.0, 0.0, 0.0, 0.0, 0.0},
                            DensityLayer{0.0, 0.0, 0.0, 0.0, 1.0}})};
    add(a);
  }
  add(Planet("no-constituents", "an atmosphere with no constituents (vacuum)", kEarthRadius, kEarthRadius + 60e3));
  {
    Atmosphere a = Planet("absorption-only", "a uniform absorber that does not scatter, optical depth 1.2",
                          kEarthRadius, kEarthRadius + 60e3);
    a.constituents = {Uniform("absorber", Spectrum(0.0), kBlueHeavy * 2e-5, kIsotropic)};
    add(a);
  }
  {
    Atmosphere a = Planet("black-ground", "Earth air over a ground of albedo 0", kEarthRadius, kEarthRadius + 60e3);
    a.constituents = {EarthAir()};
    a.ground_albedo = Spectrum(0.0);
    add(a);
  }
  {  // Tables down to the antisolar point, so that the whole night side is covered.
    Atmosphere a = Planet("white-ground", "non-absorbing Earth air over a ground of albedo 1, sun down to 180 deg",
                          kEarthRadius, kEarthRadius + 60e3);
    a.constituents = {EarthAir()};
    a.ground_albedo = Spectrum(1.0);
    a.mu_s_min = -1.0;
    add(a, true);
  }
  return set;
}

BakeSettings StressBakeSettings() {
  BakeSettings s;
  s.transmittance_width = 64, s.transmittance_height = 16;
  s.irradiance_width = 16, s.irradiance_height = 4;
  s.scattering_r_size = 8, s.scattering_mu_size = 32, s.scattering_mu_s_size = 8, s.scattering_nu_size = 4;
  s.ray_samples = 32;
  s.sphere_samples = 8;
  s.orders = 0;  // auto
  return s;
}

BakeSettings WithEnergyBalanceResolution(const StressAtmosphere& stress, BakeSettings settings) {
  if (stress.must_balance_energy) {
    // The balance converges with the mu and mu_s resolution and the sphere
    // samples, which the stress tables have too few of for 1 %.
    settings.scattering_mu_size = std::max(settings.scattering_mu_size, 64);
    settings.scattering_mu_s_size = std::max(settings.scattering_mu_s_size, 64);
    settings.sphere_samples = std::max(settings.sphere_samples, 16);
  }
  return settings;
}

StressResult RunStress(const StressAtmosphere& stress, const BakeSettings& settings, int queries,
                       std::uint64_t seed) {
  auto start = std::chrono::steady_clock::now();
  StressResult result;
  LutSet luts = Bake(stress.atmosphere, settings, &result.bake);
  result.tables = CheckTableInvariants(luts, result.bake);
  result.queries = CheckTwinInvariants(luts, result.bake, queries, seed);
  result.energy = ComputeEnergyBalance(luts);
  if (stress.must_balance_energy) {
    for (int c = 0; c < 3; ++c) {
      if (!(std::abs(result.energy.Outgoing()[c] - 1.0) <= kEnergyBalanceTolerance)) result.energy_balanced = false;
    }
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace skybake
