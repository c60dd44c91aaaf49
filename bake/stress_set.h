// The stress set: atmospheres nobody would design on purpose, each pushing
// one part of the bake to an extreme (optical depth >> 1, albedo -> 1,
// g -> +-1, tiny and huge planets, paper-thin and very thick shells, a vacuum
// gap, nothing at all, absorption only, black and white ground). Built in
// code from round numbers so that each one states what it stresses;
// `skybake stress` and tests/stress_set_test.cpp bake them and check the
// invariants of bake/invariants.h on every texel and on random queries.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "bake/bake.h"
#include "bake/energy_balance.h"
#include "bake/invariants.h"

namespace skybake {

struct StressAtmosphere {
  Atmosphere atmosphere;  // validated; atmosphere.description says what it stresses
  // Non-absorbing atmosphere over a ground of albedo 1: everything the sun
  // sends in must leave through the top (bake/energy_balance.h).
  bool must_balance_energy = false;
};

std::vector<StressAtmosphere> StressSet();

// Small tables (8 x 32 x 8 x 4 scattering, 64 x 16 transmittance, 16 x 4
// irradiance) and --orders auto: each atmosphere bakes in about a second.
BakeSettings StressBakeSettings();

// `settings` with at least the resolution at which the energy balance of
// an atmosphere that must balance converges to well within
// kEnergyBalanceTolerance (docs/stability.md, "Energy balance"); other
// atmospheres' settings unchanged.
BakeSettings WithEnergyBalanceResolution(const StressAtmosphere& stress, BakeSettings settings);

struct StressResult {
  BakeReport bake;
  InvariantReport tables;   // every texel
  InvariantReport queries;  // random twin queries
  EnergyBalance energy;
  // Only for must_balance_energy: |outgoing - 1| within kEnergyBalanceTolerance
  // in every channel (always true otherwise).
  bool energy_balanced = true;
  double seconds = 0.0;  // bake and checks

  std::int64_t Violations() const { return tables.violations + queries.violations + (energy_balanced ? 0 : 1); }
};

// Bakes one atmosphere with `settings` as given and checks it: invariants on
// every texel and on `queries` random twin queries, and the energy balance.
StressResult RunStress(const StressAtmosphere& stress, const BakeSettings& settings, int queries,
                       std::uint64_t seed);

}  // namespace skybake
