// Exact column integrals of one constituent's density along rays from an
// observer inside a spherical atmosphere: the data the sky-dome fit targets.
//
// Two ratios come out of the same slant column:
//   relative optical path  m(θ, h) = slant column / vertical column above h
//   optical length         R(θ, h) = slant column / density at h
// R is Hoffman & Preetham's optical length (the radius of their sky dome;
// 8.4 km at the zenith for air). It is undefined where the density at the
// observer is zero (the ozone tent below 10 km), while m is defined wherever
// any of the constituent lies above the observer, equals 1 at the zenith for
// every profile and is what Iqbal's formula approximates. The fit therefore
// targets m; R follows as m(θ, h) * R(0, h).
//
// Only rays at or above the horizon (θ <= 90°, μ = cos θ >= 0) are sampled:
// below the horizon a ray from an observer at the ground hits the planet, and
// from higher up its column depends on the ground intersection, which a dome
// surface does not represent. Callers clamp μ to [0, 1].
#pragma once

#include <optional>
#include <vector>

#include "bake/atmosphere.h"
#include "fit/quadrature.h"

namespace skybake::fit {

struct ColumnSample {
  double slant_column_m = 0.0;     // ∫ density ds along the ray to the top
  double vertical_column_m = 0.0;  // ∫ density dz from the observer to the top
  double density_at_observer = 0.0;
  bool converged = true;           // both quadratures met their tolerance

  // slant / vertical; empty where no density lies above the observer (0 / 0).
  std::optional<double> RelativeOpticalPath() const;
  // slant / density at the observer (metres); empty where that density is 0.
  std::optional<double> OpticalLength() const;
};

class ColumnIntegrator {
 public:
  // Throws InputError unless 0 < bottom_radius_m < top_radius_m (finite).
  ColumnIntegrator(const DensityProfile& profile, double bottom_radius_m, double top_radius_m,
                   const QuadratureOptions& options = {});

  double thickness_m() const { return top_radius_m_ - bottom_radius_m_; }

  // Altitudes in [0, thickness] where the density has a kink or jump: layer
  // boundaries, tabulated samples, and points where a layer's expression
  // crosses the clamp limits 0 or 1. Sorted, unique.
  const std::vector<double>& kinks() const { return kinks_; }

  // Both clamp the altitude to [0, thickness] and μ to [0, 1].
  QuadratureResult VerticalColumn(double altitude_m) const;
  QuadratureResult SlantColumn(double altitude_m, double mu) const;
  ColumnSample Sample(double altitude_m, double mu) const;

  // Distance from an observer at `altitude_m` along direction μ >= 0 to the
  // sphere of radius bottom + `target_altitude_m` >= altitude_m, written
  // without the cancellation of the textbook -rμ + sqrt(...) form.
  double DistanceToAltitude(double altitude_m, double mu, double target_altitude_m) const;

 private:
  DensityProfile profile_;  // a copy: integrators outlive temporaries
  double bottom_radius_m_;
  double top_radius_m_;
  QuadratureOptions options_;
  std::vector<double> kinks_;
};

}  // namespace skybake::fit
