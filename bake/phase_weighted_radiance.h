// The phase-weighted mean of the incoming radiance sampled on a sphere of
// directions, for the scattering density.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "bake/atmosphere.h"
#include "bake/detail.h"
#include "shaders_runtime/primitives.h"

namespace skybake::detail {

// The incoming radiance at a point, sampled in a set of directions with
// their solid angles, and its mean over them weighted by a phase function
// around a view direction. The discrete phase weights are normalised to sum
// to one, so the quadrature neither creates nor loses energy for sharp lobes.
class PhaseWeightedRadiance {
 public:
  PhaseWeightedRadiance(const std::vector<vec3>& directions, const std::vector<vec3>& radiance,
                        const std::vector<double>& solid_angles) {
    const std::size_t n = directions.size();
    for (auto* v : {&x_, &y_, &z_, &r_, &g_, &b_, &w_}) v->resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const vec3& d = directions[i];
      const vec3& l = radiance[i];
      const double w = solid_angles[i];
      x_[i] = float(d.x), y_[i] = float(d.y), z_[i] = float(d.z);
      r_[i] = float(l.x), g_[i] = float(l.y), b_[i] = float(l.z), w_[i] = float(w);
      // Moments for the Rayleigh and isotropic phases, whose weighted sums
      // are quadratic forms of the view direction.
      const double dd[6] = {d.x * d.x, d.y * d.y, d.z * d.z, d.x * d.y, d.x * d.z, d.y * d.z};
      weight_ += w;
      sum_ += l * w;
      for (int j = 0; j < 6; ++j) {
        weight_moments_[j] += w * dd[j];
        moments_[j] += l * (w * dd[j]);
      }
    }
  }

  vec3 Mean(const PhaseFunction& phase, const vec3& view) const {
    switch (phase.kind) {
      case PhaseKind::kIsotropic:
        return weight_ > 0.0 ? sum_ / weight_ : vec3(0.0);
      case PhaseKind::kRayleigh: {
        // Phase proportional to 1 + (v.d)^2.
        const double vv[6] = {view.x * view.x,       view.y * view.y,       view.z * view.z,
                              2.0 * view.x * view.y, 2.0 * view.x * view.z, 2.0 * view.y * view.z};
        vec3 sum = sum_;
        double weight = weight_;
        for (int j = 0; j < 6; ++j) {
          sum += moments_[j] * vv[j];
          weight += weight_moments_[j] * vv[j];
        }
        return weight > 0.0 ? sum / weight : vec3(0.0);
      }
      case PhaseKind::kHenyeyGreenstein:
        return LobeMean(phase.g, false, view);
      case PhaseKind::kCornetteShanks:
        return LobeMean(phase.g, true, view);
    }
    return vec3(0.0);
  }

 private:
  // The mean weighted by a Henyey-Greenstein or Cornette-Shanks lobe: the
  // runtime's phase functions, in float.
  vec3 LobeMean(double g, bool cornette_shanks, const vec3& view) const {
    const float gf = float(g);
    if (cornette_shanks) return WeightedMean([gf](float c) { return glsl_float::CornetteShanksPhaseFunction(gf, c); }, view);
    return WeightedMean([gf](float c) { return glsl_float::HenyeyGreensteinPhaseFunction(gf, c); }, view);
  }

  // The mean weighted by phase(cosine to the view); a float loop the
  // compiler vectorises.
  template <class Phase>
  vec3 WeightedMean(Phase phase, const vec3& view) const {
    const float vx = float(view.x), vy = float(view.y), vz = float(view.z);
    float sr = 0.0f, sg = 0.0f, sb = 0.0f, sw = 0.0f;
    const std::size_t n = x_.size();
#pragma omp simd reduction(+ : sr, sg, sb, sw)
    for (std::size_t i = 0; i < n; ++i) {
      const float w = w_[i] * phase(vx * x_[i] + vy * y_[i] + vz * z_[i]);
      sr += w * r_[i];
      sg += w * g_[i];
      sb += w * b_[i];
      sw += w;
    }
    return sw > 0.0f ? vec3(sr, sg, sb) / double(sw) : vec3(0.0);
  }

  std::vector<float> x_, y_, z_, r_, g_, b_, w_;
  double weight_ = 0.0;
  vec3 sum_{0.0};
  double weight_moments_[6] = {};
  vec3 moments_[6] = {vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0), vec3(0.0)};
};
}  // namespace skybake::detail
