// The atmosphere as the reference solver sees it: extinction and scattering
// evaluated straight from the Atmosphere description, concentric shells with
// an extinction majorant each for delta tracking, and optical depths by
// adaptive Gauss-Kronrod quadrature. Of the table path it shares only the
// Atmosphere and the ray-sphere primitives of shaders_runtime/geometry.glsl.
//
// Rays are given as (r, mu): the distance of the origin to the planet centre
// and the cosine of the angle between the ray and the origin's zenith; the
// radius at distance t is sqrt((t + r mu)^2 + r^2 (1 - mu^2)).
#pragma once

#include <vector>

#include "bake/atmosphere.h"
#include "reference/random.h"
#include "shaders_runtime/glsl_shim.h"

namespace skybake::reference {

struct OpticalDepthEstimate {
  Spectrum value{0.0};
  // Sum over the accepted pieces of |Kronrod - Gauss|: it bounds the error of
  // the 7-point rule, so it overstates the 15-point rule's error by orders of
  // magnitude on smooth pieces. Reported as a safe upper estimate.
  Spectrum error{0.0};
  int evaluations = 0;
};

enum class RayEnd {
  kCollision,  // a real collision inside the atmosphere at `distance`
  kGround,     // reached the ground at `distance`
  kSpace,      // left through the top of the atmosphere at `distance`
  kLimit,      // reached the requested maximum distance
};

struct RayEvent {
  RayEnd end = RayEnd::kLimit;
  double distance = 0.0;
  double extinction = 0.0;  // at a collision: the extinction coefficient there
};

class LayeredMedium {
 public:
  // The atmosphere must be valid (see Validate in bake/config.h).
  explicit LayeredMedium(const Atmosphere& atmosphere);

  const Atmosphere& atmosphere() const { return atmosphere_; }
  double bottom_radius() const { return geometry_.bottom_radius; }
  double top_radius() const { return geometry_.top_radius; }
  // Radii and sun size in the form the GLSL geometry primitives take.
  const glsl::AtmosphereParameters& geometry() const { return geometry_; }
  int constituent_count() const { return static_cast<int>(constituents_.size()); }
  const PhaseFunction& phase(int constituent) const { return constituents_[constituent].phase; }

  // Coefficients at a distance `radius` from the planet centre.
  Spectrum Extinction(double radius) const;
  double Extinction(double radius, int wavelength) const;
  // Scattering coefficient of every constituent at one wavelength into
  // `per_constituent` (constituent_count() values); returns their sum.
  double Scattering(double radius, int wavelength, double* per_constituent) const;

  // Optical depth along the ray (r, mu) between distances t0 <= t1, split at
  // the ray's lowest point and wherever it crosses a profile breakpoint or a
  // kink of a clamped layer, each piece refined until |Kronrod - Gauss| is
  // below relative_tolerance times the total (per wavelength).
  OpticalDepthEstimate OpticalDepth(double r, double mu, double t0, double t1, double relative_tolerance) const;

  // Delta (Woodcock) tracking from the origin of the ray (r, mu), which must
  // lie inside the atmosphere: the first real collision at one wavelength, or
  // where the ray leaves the atmosphere, or t_max, whichever comes first.
  RayEvent SampleFreeFlight(double r, double mu, double t_max, int wavelength, Pcg32& rng) const;
  // Ratio tracking: an unbiased estimate of the transmittance of the ray
  // (r, mu) from its origin to t_max or the top of the atmosphere, with
  // Russian roulette once the estimate falls below 1e-2. The ground does not
  // stop it, so a ray grazing the ground (the horizon ray toward a setting
  // sun) is not cut at its tangent point by rounding.
  double RatioTrackingTransmittance(double r, double mu, double t_max, int wavelength, Pcg32& rng) const;

  // Distances along the ray (r, mu) where it crosses a shell boundary, up to
  // t_max or where it leaves the atmosphere (that distance included).
  std::vector<double> ShellCrossings(double r, double mu, double t_max) const;

  // The delta-tracking shells: radii bottom..top (shell_count() + 1 values),
  // and the extinction majorant of each shell.
  int shell_count() const { return static_cast<int>(shell_radii_.size()) - 1; }
  const std::vector<double>& shell_radii() const { return shell_radii_; }
  double Majorant(int shell, int wavelength) const { return majorants_[3 * shell + wavelength]; }
  int ShellIndex(double radius) const;

 private:
  struct Coefficients {
    DensityProfile density;
    Spectrum extinction{0.0};
    Spectrum scattering{0.0};
    PhaseFunction phase;
  };

  template <typename Visit>
  RayEvent Traverse(double r, double mu, double t_max, bool stop_at_ground, Visit&& visit) const;
  void BuildShells();

  Atmosphere atmosphere_;
  glsl::AtmosphereParameters geometry_;
  std::vector<Coefficients> constituents_;  // those with non-zero extinction
  std::vector<double> split_radii_;         // quadrature split points (breakpoints, kinks)
  std::vector<double> shell_radii_;
  std::vector<glsl::AtmosphereParameters> shell_geometry_;  // one sphere pair per shell
  std::vector<double> majorants_;                            // [shell][wavelength]
};

// Radius at distance t along the ray (r, mu), accurate near the tangent point.
double RadiusAlongRay(double r, double mu, double t);

}  // namespace skybake::reference
