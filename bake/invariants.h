// Invariants every baked set must satisfy, whatever the atmosphere: checked
// on every texel of every table and on random queries through the CPU twin
// (what `skybake eval` and the GLSL snippet compute). Used by `skybake
// stress` and tests/stress_set_test.cpp; the bounds are derived in
// docs/stability.md ("Invariants").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake.h"

namespace skybake {

// Upper bounds per channel implied by energy conservation (docs/stability.md):
// no radiance can exceed what `orders` bounces of the brightest single
// scattering (or ground reflection) could carry.
struct EnergyBounds {
  Spectrum single_scattering{0.0};  // phase-free single scattering: E_sun
  Spectrum radiance{0.0};           // any radiance the twin returns
  Spectrum sky_irradiance{0.0};     // the irradiance table and sky irradiance
};
EnergyBounds ComputeEnergyBounds(const LutSet& luts, const BakeReport& report);

struct InvariantReport {
  std::int64_t values_checked = 0;
  std::int64_t violations = 0;
  std::vector<std::string> examples;  // the first few violations, one line each
  // Measured on twin queries, violation or not: the largest increase of the
  // transmittance to a farther point on the same ray, and the largest
  // difference between the transmittances of a segment read in both directions.
  double largest_transmittance_increase = 0.0;
  double largest_direction_difference = 0.0;

  void Violation(const std::string& what);
  void Merge(const InvariantReport& other);
};

// Every channel of every texel: finite and >= 0; optical depth (the
// transmittance table) so transmittance <= 1; single scattering and
// irradiance within the energy bounds.
InvariantReport CheckTableInvariants(const LutSet& luts, const BakeReport& report);

// `queries` random twin queries (deterministic for a seed): cameras on the
// ground, at the top, inside, far in space and below the ground (clamped to
// the ground as eval does), views exactly at the horizon among random ones,
// the sun down to the lowest covered zenith. Per query: radiance finite,
// >= 0 and within the bound; transmittance in [0, 1], non-increasing with
// distance along the ray and the same in both directions between two points;
// sun and sky irradiance finite, >= 0 and within their bounds.
InvariantReport CheckTwinInvariants(const LutSet& luts, const BakeReport& report, int queries, std::uint64_t seed);

}  // namespace skybake
