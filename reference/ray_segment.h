// The part of a ray inside the atmosphere, with its optical depth tabulated
// for sampling distances along it: the first vertex of every radiance path
// (on the view ray) and the forced collisions of the paths' first rays.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "bake/atmosphere.h"
#include "reference/layered_medium.h"

namespace skybake::reference {

// Relative tolerances of the optical-depth quadratures: tight for what is
// reported (transmittances, sun irradiance), looser for the ones at every
// path vertex. Either is far below the Monte Carlo noise: on Earth even
// 1e-5 gives 1e-13, as |Kronrod - Gauss| overstates the error by far.
constexpr double kReportedTolerance = 1e-10;
constexpr double kVertexTolerance = 1e-7;

// Distances where the ray (r, mu) is inside the top sphere, the ground
// ignored; false if it never is.
bool InsideTopSphere(const glsl::AtmosphereParameters& geometry, double r, double mu, double* t_in,
                     double* t_out);

// The zenith cosine of the ray along which the sun's visible part is seen
// from radius r, for the sun's zenith cosine mu_s: mu_s itself, or the
// horizon's when the disc's centre is below it (its visible part is then
// seen along the ray that grazes the ground).
double SunRayCosine(const glsl::AtmosphereParameters& geometry, double r, double mu_s);

// A ray clipped to the atmosphere (a camera in space starts where the ray
// enters it) and ending at the ground, the top, or the given distance, with
// its optical depth at nodes: the shell crossings, refined so that
// neighbours differ by a bounded optical depth. Distances are sampled with
// density extinction x transmittance under the table's piecewise-linear
// optical depth, optionally guided (MakeMixture); the table defines only
// that density, and every weight uses the exact transmittance, so a coarse
// table costs variance, never bias.
class RaySegment {
 public:
  enum class Table {
    kExact,     // nodes by adaptive quadrature (reported, built once per query)
    kSampling,  // nodes by the midpoint rule per shell (for the rays of paths)
  };

  // distance 0: the whole ray.
  RaySegment(const LayeredMedium& medium, const glm::dvec3& start, const glm::dvec3& direction, double distance,
             Table table);

  double length() const { return length_; }
  bool hits_ground() const { return hits_ground_; }
  const glm::dvec3& origin() const { return origin_; }
  double r() const { return r_; }    // of the origin
  double mu() const { return mu_; }  // of the direction at the origin

  // Transmittance of the segment and its estimated error (exact tables); 0
  // for a whole ray that ends on the ground.
  Spectrum Transmittance(Spectrum* error) const;

  // The middle distance of each piece between two nodes of the table.
  std::vector<double> PieceMiddles() const;

  // A density over distances for wavelength w: a mixture with share `keep`
  // of extinction x transmittance (under the table's piecewise-linear
  // optical depth tau~: slope exp(-tau~(t)) / (1 - exp(-tau~(length))), the
  // truncated exponential in tau~), and otherwise that density times
  // piece_weights[k] on piece k (normalised), for the pieces a path should
  // find more often (the sunlit ones after sunset). Without weight on any
  // piece where the first density is not 0 it is the first density.
  struct Mixture {
    int wavelength = 0;
    std::vector<double> cumulative;  // of the pieces' masses, ending at 1
    std::vector<double> factor;      // on each piece, the mixture / the first density
  };
  Mixture MakeMixture(int w, const std::vector<double>& piece_weights, double keep) const;

  // A distance t from u in [0, 1) and T(t) / pdf(t) under the mixture;
  // false if the segment has no extinction at its wavelength.
  bool SampleMixture(const LayeredMedium& medium, const Mixture& mixture, double u, double* t,
                     double* transmittance_over_pdf) const;

 private:
  // The distance within piece k at the table's optical depth `target`, and
  // T(t) / pdf(t) under extinction x transmittance.
  void SampleInPiece(const LayeredMedium& medium, int w, std::size_t k, double target, double* t,
                     double* transmittance_over_pdf) const;

  Table table_;
  glm::dvec3 origin_{0.0};
  double r_ = 0.0, mu_ = 0.0, length_ = 0.0;
  bool hits_ground_ = false, whole_ray_ = true;
  std::vector<double> t_;
  std::vector<double> tau_[kWavelengthCount];
  Spectrum tau_error_{0.0};
};

}  // namespace skybake::reference
