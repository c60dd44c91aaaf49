#include "reference/ray_segment.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "shaders_runtime/runtime.h"

namespace skybake::reference {

namespace {
// Tables have nodes at most this optical depth apart, up to a depth beyond
// which nothing is sampled in practice: fine for the view ray, built once
// per query, whose every shell crossing is also split in at least
// kViewPiecesPerShell pieces so that the density follows the extinction
// within a shell and the stratified first vertex is nearly noise free;
// coarse for the rays of paths.
constexpr double kViewStep = 0.01, kViewDepth = 40.0;
constexpr int kViewPiecesPerShell = 8;
constexpr double kPathStep = 0.5, kPathDepth = 20.0;
}  // namespace

bool InsideTopSphere(const glsl::AtmosphereParameters& g, double r, double mu, double* t_in, double* t_out) {
  if (r <= g.top_radius) {
    *t_in = 0.0;
    *t_out = glsl::DistanceToTopAtmosphereBoundary(g, r, mu);
    return true;
  }
  double r_mu = r * mu;
  double c = (r - g.top_radius) * (r + g.top_radius);
  double disc = r_mu * r_mu - c;
  if (r_mu >= 0.0 || disc < 0.0) return false;
  double s = std::sqrt(disc);
  *t_in = c / (s - r_mu);
  *t_out = s - r_mu;
  return true;
}

double SunRayCosine(const glsl::AtmosphereParameters& g, double r, double mu_s) {
  return glsl::RayIntersectsGround(g, r, mu_s) ? glsl::HorizonZenithCosine(g.bottom_radius, r) : mu_s;
}

RaySegment::RaySegment(const LayeredMedium& medium, const glm::dvec3& start, const glm::dvec3& direction,
                       double distance, Table table)
    : table_(table) {
  const glsl::AtmosphereParameters& g = medium.geometry();
  double r_start = glm::length(start);
  double mu_start = std::clamp(glm::dot(start, direction) / r_start, -1.0, 1.0);
  double t_in, t_out;
  if (!InsideTopSphere(g, r_start, mu_start, &t_in, &t_out)) return;
  if (t_in > 0.0) {
    r_ = g.top_radius;
    mu_ = std::clamp((r_start * mu_start + t_in) / r_, -1.0, 1.0);
  } else {
    r_ = r_start;
    mu_ = mu_start;
  }
  origin_ = start + t_in * direction;
  hits_ground_ = glsl::RayIntersectsGround(g, r_, mu_);
  double boundary = hits_ground_ ? glsl::DistanceToBottomAtmosphereBoundary(g, r_, mu_)
                                 : glsl::DistanceToTopAtmosphereBoundary(g, r_, mu_);
  length_ = distance > 0.0 ? std::clamp(distance - t_in, 0.0, boundary) : boundary;
  whole_ray_ = distance <= 0.0;
  if (!(length_ > 0.0)) return;

  const bool exact = table_ == Table::kExact;
  auto piece_depth = [&](double a, double b) {
    if (exact) return medium.OpticalDepth(r_, mu_, a, b, kReportedTolerance);
    // Within a shell the extinction varies by at most ~20%: the midpoint
    // rule gives a density within a fraction of a percent of the ideal one.
    OpticalDepthEstimate estimate;
    estimate.value = (b - a) * medium.Extinction(RadiusAlongRay(r_, mu_, 0.5 * (a + b)));
    return estimate;
  };
  Spectrum tau(0.0);
  auto add_node = [&](double t, const OpticalDepthEstimate& piece) {
    tau += piece.value;
    tau_error_ += piece.error;
    t_.push_back(t);
    for (int w = 0; w < kWavelengthCount; ++w) tau_[w].push_back(tau[w]);
  };
  add_node(0.0, OpticalDepthEstimate());
  const double max_step = exact ? kViewStep : kPathStep, max_depth = exact ? kViewDepth : kPathDepth;
  for (double end : medium.ShellCrossings(r_, mu_, length_)) {
    double begin = t_.back();
    end = std::min(end, length_);
    if (!(end > begin)) continue;
    OpticalDepthEstimate piece = piece_depth(begin, end);
    double step = std::max({piece.value.x, piece.value.y, piece.value.z});
    double depth = std::max({tau.x, tau.y, tau.z});
    int parts = step > max_step && depth < max_depth ? static_cast<int>(std::min(256.0, std::ceil(step / max_step)))
                                                     : 1;
    if (exact) parts = std::max(parts, kViewPiecesPerShell);
    if (parts == 1) {
      add_node(end, piece);
      continue;
    }
    for (int k = 1; k <= parts; ++k) {
      double a = t_.back(), b = k == parts ? end : begin + (end - begin) * k / parts;
      add_node(b, piece_depth(a, b));
    }
  }
}

Spectrum RaySegment::Transmittance(Spectrum* error) const {
  *error = Spectrum(0.0);
  if (whole_ray_ && hits_ground_) return Spectrum(0.0);
  if (t_.empty()) return Spectrum(1.0);
  Spectrum transmittance = glm::exp(-Spectrum(tau_[0].back(), tau_[1].back(), tau_[2].back()));
  *error = transmittance * tau_error_;
  return transmittance;
}

void RaySegment::SampleInPiece(const LayeredMedium& medium, int w, std::size_t k, double target, double* t,
                               double* transmittance_over_pdf) const {
  const std::vector<double>& tau = tau_[w];
  double norm = -std::expm1(-tau.back());
  double slope = (tau[k + 1] - tau[k]) / (t_[k + 1] - t_[k]);
  *t = std::clamp(t_[k] + (target - tau[k]) / slope, t_[k], t_[k + 1]);
  double approximate = tau[k] + (*t - t_[k]) * slope;
  double exact = table_ == Table::kExact
                     ? tau[k] + medium.OpticalDepth(r_, mu_, t_[k], *t, kVertexTolerance).value[w]
                     : medium.OpticalDepth(r_, mu_, 0.0, *t, kVertexTolerance).value[w];
  *transmittance_over_pdf = std::exp(-(exact - approximate)) * norm / slope;
}

std::vector<double> RaySegment::PieceMiddles() const {
  std::vector<double> middles;
  for (std::size_t k = 0; k + 1 < t_.size(); ++k) middles.push_back(0.5 * (t_[k] + t_[k + 1]));
  return middles;
}

RaySegment::Mixture RaySegment::MakeMixture(int w, const std::vector<double>& piece_weights, double keep) const {
  // Piece k holds mass P_k = exp(-tau_k) - exp(-tau_k+1) of the first
  // density (times its norm); the guided density gives it P_k g_k / G with
  // G = sum P_k g_k, so on piece k the mixture is the first density times
  // c_k = keep + (1 - keep) g_k norm / G.
  Mixture mixture;
  mixture.wavelength = w;
  if (t_.size() < 2) return mixture;
  const std::vector<double>& tau = tau_[w];
  const double norm = -std::expm1(-tau.back());
  if (!(norm > 0.0)) return mixture;
  const std::size_t pieces = t_.size() - 1;
  std::vector<double> mass(pieces);
  double guided = 0.0;
  for (std::size_t k = 0; k < pieces; ++k) {
    mass[k] = std::exp(-tau[k]) * -std::expm1(-(tau[k + 1] - tau[k]));
    guided += mass[k] * piece_weights[k];
  }
  double sum = 0.0;
  for (std::size_t k = 0; k < pieces; ++k) {
    const double factor = guided > 0.0 ? keep + (1.0 - keep) * piece_weights[k] * norm / guided : 1.0;
    sum += mass[k] * factor / norm;
    mixture.factor.push_back(factor);
    mixture.cumulative.push_back(sum);
  }
  for (double& c : mixture.cumulative) c /= sum;  // 1 up to rounding
  return mixture;
}

bool RaySegment::SampleMixture(const LayeredMedium& medium, const Mixture& mixture, double u, double* t,
                               double* transmittance_over_pdf) const {
  if (mixture.cumulative.empty()) return false;
  const std::vector<double>& c = mixture.cumulative;
  std::size_t k = static_cast<std::size_t>(std::upper_bound(c.begin(), c.end(), u) - c.begin());
  k = std::min(k, c.size() - 1);
  // A u on the last edge can land on a piece without mass: step back.
  while (k > 0 && !(c[k] > c[k - 1])) --k;
  const double begin = k > 0 ? c[k - 1] : 0.0;
  const double v = c[k] > begin ? std::clamp((u - begin) / (c[k] - begin), 0.0, 1.0) : 0.5;
  // Within the piece, the first density: the truncated exponential in tau~.
  const std::vector<double>& tau = tau_[mixture.wavelength];
  SampleInPiece(medium, mixture.wavelength, k, tau[k] - std::log1p(v * std::expm1(-(tau[k + 1] - tau[k]))), t,
                transmittance_over_pdf);
  *transmittance_over_pdf /= mixture.factor[k];
  return true;
}

}  // namespace skybake::reference
