// The scattering density's phase-weighted mean of the incoming radiance on
// the rings of a sphere rule, with the integral along each ring's azimuth
// taken in Fourier terms.
#pragma once

#include <cstddef>
#include <vector>

#include "bake/atmosphere.h"
#include "core/spectrum.h"

namespace skybake::detail {

// c_k = integral over psi in [0, 2 pi) of p(cos gamma) cos(k psi), k = 0 ...
// terms - 1, with cos gamma = view_mu ring_cos + sin(view) sin(ring) cos psi:
// the azimuthal Fourier cosine coefficients of phase function p between a
// view of zenith cosine view_mu and the ring of directions of zenith cosine
// ring_cos (psi the azimuth between them). By the midpoint rule in s with
// tan(psi / 2) = lambda tan(s / 2), which is periodic and puts more nodes
// where a lobe peaks (lambda the square root of its half width in tan(psi /
// 2)); the smooth phases (cosine series of degree 2 and 0) on the plain
// midpoint rule (lambda = 1), which integrates them exactly.
class PhaseAzimuthSeries {
 public:
  PhaseAzimuthSeries(const PhaseFunction& phase, int terms);
  // c[k], k < the terms it was built for.
  void Coefficients(double view_mu, double ring_cos, double* c) const;

 private:
  PhaseFunction phase_;
  int terms_;
  bool lobe_;
  // tan(s_q / 2) at the midpoint nodes s_q over [0, pi], per rule (for a
  // lobe, from 64 nodes up in powers of two, the narrower the lobe and the
  // more terms the more: ring_phase.cpp).
  std::vector<std::vector<double>> tan_half_s_;
};

// The phase-weighted mean of the radiance L arriving at a point from the
// rings of a sphere rule: rings of zenith cosine cos_l with weights w_l in
// cos(theta), each sampled at the azimuths phi_m = (m + 1/2) 2 pi / (2 K)
// from the sun's, symmetric about the sun's plane (L(phi) = L(-phi), so
// only m < K are given). On each ring L is taken as the cosine series
// through its samples, L_l(phi) = sum_k a_lk cos(k phi), k < K (a DCT-II of
// the K samples), whose integral against the phase around a view at
// azimuth phi_v is sum_k a_lk c_lk cos(k phi_v) (PhaseAzimuthSeries):
//
//   mean(view) = sum_l w_l sum_k a_lk c_lk cos(k phi_v) / sum_l w_l c_l0.
//
// The denominator normalises the phase's weights to sum to one, so that the
// rule neither creates nor loses energy for a lobe narrower than the polar
// nodes. For the Rayleigh and isotropic phases (cosine series of degree 2
// and 0) this is the rule's discrete sum over its 2 K azimuths exactly; a
// lobe is integrated along the azimuth exactly for the series, where a sum
// over the azimuths would have needed a phase value per direction and view.
//
// A medium's groups scatter with different phases: the scattering density
// per unit scattering is the sum of their means, each weighted by its share
// of the scattering per channel, which depends only on the altitude. So the
// shares are folded into the weights, per channel, once per rule.
class RingPhaseMeans {
 public:
  // For every view zenith cosine and channel, the weights sum_g share_g
  // w_l c_lk / sum_l w_l c_l0 of the groups' phases `series` (all of
  // `terms` terms) and shares (per channel) of the scattering.
  RingPhaseMeans(const std::vector<PhaseAzimuthSeries>& series, const std::vector<Spectrum>& shares,
                 const std::vector<double>& view_mu, const std::vector<double>& ring_cos,
                 const std::vector<double>& ring_weights, int terms);

  // The terms of a ring's series are stored at this stride, a whole number
  // of vectors (kTermBlock floats), the terms past `terms` zero.
  int Stride() const { return stride_; }
  static constexpr int kTermBlock = 16;
  static int StrideFor(int terms) { return (terms + kTermBlock - 1) / kTermBlock * kTermBlock; }
  // The bytes of the weights of `views` views.
  static std::size_t WeightBytes(std::size_t views, int rings, int terms) {
    return views * 3 * rings * StrideFor(terms) * sizeof(float);
  }

  // The terms of the mean for a view of zenith cosine view_mu[view], per
  // channel c: out[c * Stride() + k] = sum_l weight_clk a[(c * rings + l)
  // * Stride() + k].
  void Terms(int view, const float* a, float* out) const;

 private:
  int rings_, stride_;
  std::vector<float> weights_;  // at [((view * 3 + channel) * rings + l) * stride + k]
};

// cos(k phi_i), k < terms, for count azimuths given by cos(phi_i), into
// out[k * count + i]: by cos((k + 1) phi) = 2 cos(phi) cos(k phi) - cos((k -
// 1) phi), all azimuths at once.
void CosineMultiples(const double* cos_phi, int count, int terms, double* out);

// The cosine series a_k, k < K, through K samples at phi_m = (m + 1/2) pi / K
// (the DCT-II and its normalisation): samples[m] = sum_k a_k cos(k phi_m).
class AzimuthCosineSeries {
 public:
  explicit AzimuthCosineSeries(int samples);
  // a[k] from samples[m].
  void Coefficients(const double* samples, float* a) const;

 private:
  int samples_;
  std::vector<double> basis_;  // (2 or 1) / K cos(k phi_m) at [k * K + m]
};
}  // namespace skybake::detail
