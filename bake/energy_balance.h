// The energy balance of a baked set at the top of the atmosphere: the
// radiant flux that leaves the planet through the top sphere against the
// flux pi R_top^2 E_sun the sun sends in. Computed from the tables through
// the CPU twin, as an engine would see the planet from space. A
// non-absorbing atmosphere over a ground of albedo 1 must send everything
// back (ratio 1); otherwise 1 - ratio is the fraction absorbed by the air
// and the ground. Method and quadrature in docs/stability.md ("Energy balance").
#pragma once

#include "bake/bake.h"

namespace skybake {

struct EnergyBalance {
  // Per channel, relative to the incoming flux pi R_top^2 E_sun:
  Spectrum scattered{0.0};    // sky radiance and ground reflection leaving the top
  Spectrum transmitted{0.0};  // sunlight crossing the limb unscattered
  // The part of the top sphere where the sun is lower than the tables cover
  // (mu_s < mu_s_min, deep night) is not counted: its fraction of the
  // sphere's area, 0 when mu_s_min = -1.
  double uncovered_area = 0.0;
  Spectrum Outgoing() const { return scattered + transmitted; }
};

// `sun_samples` sun zenith cosines over [mu_s_min, 1] and `direction_samples`
// outgoing zenith cosines per side of the ground's horizon (azimuths: as
// many over [0, pi], the field being symmetric about the sun's plane).
// A non-absorbing atmosphere over a white ground must balance to this
// fraction of the incoming flux once its orders have converged (issue #7).
constexpr double kEnergyBalanceTolerance = 0.01;

EnergyBalance ComputeEnergyBalance(const LutSet& luts, int sun_samples = 128, int direction_samples = 24);

}  // namespace skybake
