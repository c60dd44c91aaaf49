// The atmosphere as the integrators see it: constituents grouped by phase
// function, so that each group's phase is evaluated once per direction pair.
#pragma once

#include <vector>

#include "bake/atmosphere.h"

namespace skybake {

struct PhaseGroup {
  PhaseFunction phase;
  std::vector<int> constituents;  // indices into Atmosphere::constituents
};

class Medium {
 public:
  explicit Medium(const Atmosphere& atmosphere);

  const Atmosphere& atmosphere() const { return atmosphere_; }
  int constituent_count() const { return static_cast<int>(atmosphere_.constituents.size()); }

  // Groups of scattering constituents with identical phase functions. The
  // Mie group (if any) holds the constituents sharing the first
  // Henyey-Greenstein or Cornette-Shanks phase function; its single
  // scattering goes to its own table with the phase applied at run time.
  const std::vector<PhaseGroup>& groups() const { return groups_; }
  int mie_group() const { return mie_group_; }  // -1 if none

  // Relative density of every constituent at an altitude, into `densities`.
  void Densities(double altitude_m, double* densities) const;
  Spectrum Extinction(const double* densities) const;
  Spectrum GroupScattering(int group, const double* densities) const;

  // Optical depth along the ray from radius r with direction cosine mu over
  // distance d, by Gauss-Legendre quadrature on pieces split where the ray
  // crosses a profile breakpoint or reaches its lowest altitude.
  Spectrum OpticalDepth(double r, double mu, double d, int nodes) const;

 private:
  Atmosphere atmosphere_;
  std::vector<PhaseGroup> groups_;
  int mie_group_ = -1;
  std::vector<double> breakpoint_radii_;
};

}  // namespace skybake
