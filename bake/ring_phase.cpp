#include "bake/ring_phase.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "core/constants.h"
#include "shaders_runtime/primitives.h"

namespace skybake::detail {
namespace {
// Midpoint nodes in s over [0, pi] (the integrand is even in psi). With
// the map's lambda = sqrt(half width) the error in s decays as fast on the
// lobe's side as on the far side, where cos(k psi) is squeezed by 1 /
// lambda. A lobe takes the larger of kNodesPerLambda / lambda and terms /
// lambda nodes, from 64 up in powers of two: that puts every c_k within
// 1e-9 of c_0 of the plain midpoint rule on 2^17 nodes for
// Henyey-Greenstein lobes with g from 0.5 to 0.999 and 16 terms (64 nodes
// for Earth's haze, g = 0.8, 512 for g = 0.999), and within 1e-7 for 64
// terms (tests/ring_phase_test.cpp). The smooth phases take enough that the
// rule is exact for the integrand's cosine series (degree 2 + k < 2 *
// nodes).
constexpr double kNodesPerLambda = 20.0;
constexpr int kFewestLobeNodes = 64, kMostNodes = 1 << 16;
// Nodes are summed in blocks of this many (their values on the stack).
constexpr int kNodeBlock = 256;

// Half width in t = tan(psi / 2) of a Henyey-Greenstein or Cornette-Shanks
// lobe around psi = 0 (with cos gamma = a + b cos psi, b >= 0, g > 0):
// 1 + g^2 - 2 g cos gamma = e + 4 g b t^2 / (1 + t^2), e its value at psi =
// 0, which doubles at t^2 = e / (4 g b) for small t.
double LobeHalfWidth(double g, double a, double b) {
  if (g <= 0.0 || b <= 0.0) return 1.0;
  const double e = std::max(0.0, 1.0 + g * g - 2.0 * g * (a + b));
  return std::sqrt(e / (4.0 * g * b));
}

// The map's lambda for a lobe (cos gamma = a + b cos psi, g > 0), and the
// nodes a rule of `terms` terms needs with it.
double LobeLambda(double g, double a, double b) { return std::clamp(std::sqrt(LobeHalfWidth(g, a, b)), 1e-3, 1.0); }
double NodesNeeded(double lambda, int terms) { return std::max(kNodesPerLambda, double(terms)) / lambda; }

// sum_q p(a + b cos psi_q) (d psi / d s)_q cos(k psi_q), k < terms, into c:
// per block of nodes, a loop over them per k, which the compiler vectorises.
template <typename Phase>
void SumOverNodes(Phase phase, double a, double b, double lambda, const std::vector<double>& tan_half_s, int terms,
                  double* c) {
  std::fill(c, c + terms, 0.0);
  const int n = static_cast<int>(tan_half_s.size());
  for (int first = 0; first < n; first += kNodeBlock) {
    const int count = std::min(kNodeBlock, n - first);
    const double* tan_half = tan_half_s.data() + first;
    double cos_psi[kNodeBlock], value[kNodeBlock], previous[kNodeBlock], current[kNodeBlock];
#pragma omp simd
    for (int q = 0; q < count; ++q) {
      const double t = lambda * tan_half[q];
      cos_psi[q] = (1.0 - t * t) / (1.0 + t * t);
      // d psi / d s, psi = 2 atan(lambda tan(s / 2)).
      const double dpsi_ds = lambda * (1.0 + tan_half[q] * tan_half[q]) / (1.0 + t * t);
      value[q] = phase(std::clamp(a + b * cos_psi[q], -1.0, 1.0)) * dpsi_ds;
      previous[q] = 1.0, current[q] = cos_psi[q];
    }
    for (int k = 0; k < terms; ++k) {
      double sum = 0.0;
      if (k == 0) {
#pragma omp simd reduction(+ : sum)
        for (int q = 0; q < count; ++q) sum += value[q];
      } else {
        // cos(k psi) from the two before it.
#pragma omp simd reduction(+ : sum)
        for (int q = 0; q < count; ++q) {
          sum += value[q] * current[q];
          const double next = 2.0 * cos_psi[q] * current[q] - previous[q];
          previous[q] = current[q], current[q] = next;
        }
      }
      c[k] += sum;
    }
  }
}
}  // namespace

PhaseAzimuthSeries::PhaseAzimuthSeries(const PhaseFunction& phase, int terms)
    : phase_(phase),
      terms_(terms),
      lobe_(phase.kind == PhaseKind::kHenyeyGreenstein || phase.kind == PhaseKind::kCornetteShanks) {
  auto rule = [](int nodes) {
    std::vector<double> tan_half_s;
    for (int q = 0; q < nodes; ++q) tan_half_s.push_back(std::tan(0.5 * (q + 0.5) * kPi / nodes));
    return tan_half_s;
  };
  if (!lobe_) {
    tan_half_s_.push_back(rule(terms / 2 + 2));
    return;
  }
  // Up to the rule of the narrowest lobe: a ring through the view (a + b =
  // 1, b = 1).
  const double narrowest = NodesNeeded(LobeLambda(std::abs(phase.g), 0.0, 1.0), terms);
  for (int nodes = kFewestLobeNodes; nodes <= kMostNodes; nodes *= 2) {
    tan_half_s_.push_back(rule(nodes));
    if (nodes >= narrowest) break;
  }
}

void PhaseAzimuthSeries::Coefficients(double view_mu, double ring_cos, double* c) const {
  const double a = view_mu * ring_cos;
  const double b =
      std::sqrt(std::max(0.0, 1.0 - view_mu * view_mu)) * std::sqrt(std::max(0.0, 1.0 - ring_cos * ring_cos));
  // A lobe with g < 0 peaks at psi = pi: integrate over psi' = pi - psi,
  // where cos psi = -cos psi' and cos(k psi) = (-1)^k cos(k psi').
  const double side = lobe_ && phase_.g < 0.0 ? -1.0 : 1.0;
  const double lambda = lobe_ ? LobeLambda(std::abs(phase_.g), side * a, b) : 1.0;
  const double needed = NodesNeeded(lambda, terms_);
  std::size_t rule = 0;
  while (rule + 1 < tan_half_s_.size() && double(tan_half_s_[rule].size()) < needed) ++rule;
  const std::vector<double>& nodes = tan_half_s_[rule];
  const double g = phase_.g;
  switch (phase_.kind) {
    case PhaseKind::kIsotropic:
      SumOverNodes([](double) { return glsl::IsotropicPhaseFunction(); }, a, b, lambda, nodes, terms_, c);
      break;
    case PhaseKind::kRayleigh:
      SumOverNodes([](double x) { return glsl::RayleighPhaseFunction(x); }, a, b, lambda, nodes, terms_, c);
      break;
    case PhaseKind::kHenyeyGreenstein:
      SumOverNodes([g](double x) { return glsl::HenyeyGreensteinPhaseFunction(g, x); }, a, side * b, lambda, nodes,
                   terms_, c);
      break;
    case PhaseKind::kCornetteShanks:
      SumOverNodes([g](double x) { return glsl::CornetteShanksPhaseFunction(g, x); }, a, side * b, lambda, nodes,
                   terms_, c);
      break;
  }
  // Twice the half period's sum, times the node spacing pi / nodes.
  const double spacing = kPi / nodes.size();
  for (int k = 0; k < terms_; ++k) c[k] *= 2.0 * spacing * (k % 2 == 1 ? side : 1.0);
}

RingPhaseMeans::RingPhaseMeans(const std::vector<PhaseAzimuthSeries>& series, const std::vector<Spectrum>& shares,
                               const std::vector<double>& view_mu, const std::vector<double>& ring_cos,
                               const std::vector<double>& ring_weights, int terms)
    : rings_(static_cast<int>(ring_cos.size())), stride_(StrideFor(terms)) {
  weights_.assign(view_mu.size() * 3 * rings_ * stride_, 0.0f);
  std::vector<double> c(std::size_t(rings_) * terms);
  for (std::size_t v = 0; v < view_mu.size(); ++v) {
    for (std::size_t g = 0; g < series.size(); ++g) {
      if (shares[g] == Spectrum(0.0)) continue;
      double weight = 0.0;
      for (int l = 0; l < rings_; ++l) {
        series[g].Coefficients(view_mu[v], ring_cos[l], &c[std::size_t(l) * terms]);
        weight += ring_weights[l] * c[std::size_t(l) * terms];
      }
      if (weight <= 0.0) continue;
      for (int channel = 0; channel < 3; ++channel) {
        float* out = &weights_[(v * 3 + channel) * rings_ * stride_];
        for (int l = 0; l < rings_; ++l) {
          const double factor = shares[g][channel] * ring_weights[l] / weight;
          for (int k = 0; k < terms; ++k) out[l * stride_ + k] += float(factor * c[std::size_t(l) * terms + k]);
        }
      }
    }
  }
}

void RingPhaseMeans::Terms(int view, const float* a, float* out) const {
  const float* w = &weights_[std::size_t(view) * 3 * rings_ * stride_];
  const std::size_t channel_stride = std::size_t(rings_) * stride_;
  for (int block = 0; block < stride_; block += kTermBlock) {
    // The three channels' sums side by side: three chains of additions.
    float sum[3][kTermBlock] = {};
    for (int l = 0; l < rings_; ++l) {
      for (int c = 0; c < 3; ++c) {
        const std::size_t at = c * channel_stride + std::size_t(l) * stride_ + block;
#pragma omp simd
        for (int k = 0; k < kTermBlock; ++k) sum[c][k] += w[at + k] * a[at + k];
      }
    }
    for (int c = 0; c < 3; ++c) std::copy(sum[c], sum[c] + kTermBlock, out + c * stride_ + block);
  }
}

AzimuthCosineSeries::AzimuthCosineSeries(int samples) : samples_(samples), basis_(std::size_t(samples) * samples) {
  for (int k = 0; k < samples; ++k) {
    for (int m = 0; m < samples; ++m) {
      basis_[k * samples + m] = (k == 0 ? 1.0 : 2.0) / samples * std::cos(k * (m + 0.5) * kPi / samples);
    }
  }
}

void AzimuthCosineSeries::Coefficients(const double* samples, float* a) const {
  for (int k = 0; k < samples_; ++k) {
    double sum = 0.0;
    for (int m = 0; m < samples_; ++m) sum += basis_[k * samples_ + m] * samples[m];
    a[k] = float(sum);
  }
}

void CosineMultiples(const double* cos_phi, int count, int terms, double* out) {
  for (int i = 0; i < count; ++i) out[i] = 1.0;
  if (terms > 1) std::copy(cos_phi, cos_phi + count, out + count);
  for (int k = 2; k < terms; ++k) {
    double* multiple = out + std::size_t(k) * count;
#pragma omp simd
    for (int i = 0; i < count; ++i) multiple[i] = 2.0 * cos_phi[i] * multiple[i - count] - multiple[i - 2 * count];
  }
}
}  // namespace skybake::detail
