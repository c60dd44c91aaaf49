// Single scattering: along a ray, the light of the sun scattered once toward
// its start, for many sun directions at once: per ray of the table's grid
// for all of its texels' suns, and along the rings of the sphere rules that
// read a low sun's light (Baker::SingleScatteringOnRings).
#include "bake/baker.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/grids.h"
#include "core/constants.h"
#include "shaders_runtime/runtime.h"

namespace skybake::detail {
// Intervals of a ray that are partly shadowed (the planet's shadow edge
// crosses them, or the sun's disc is partly hidden) are integrated on this
// many sub-intervals: the shadow edge moves the integrand from lit to dark
// within one interval, which the two-point rules cannot follow. Tested
// against brute force in SingleScattering.MatchesBruteForceQuadratureWithinHalfPercent;
// twice as many move no case group by more than 0.004 % (docs/benchmark.md).
constexpr int kShadowEdgeSubdivisions = 4;

RaySamples Baker::SampleRay(const AtmosphereParameters& grid, int mu_index, int r_index, int n) const {
  const ScatteringTexel texel = GetScatteringSliceTexel(grid, 0, mu_index, r_index);
  return SampleRay(texel.r, texel.mu, texel.ray_intersects_ground, n);
}

RaySamples Baker::SampleRay(double r, double mu, bool intersects_ground, int n) const {
  RaySamples ray;
  ray.r = r, ray.mu = mu, ray.intersects_ground = intersects_ground;
  double d = glsl::DistanceToNearestAtmosphereBoundary(params_, ray.r, ray.mu, ray.intersects_ground);
  const int constituents = medium_.constituent_count();
  const int groups = static_cast<int>(medium_.groups().size());
  ray.t = RayDistances(d, n);
  ray.radius.resize(n + 1);
  ray.optical_depth.assign(n + 1, Spectrum(0.0));
  ray.extinction.resize(n + 1);
  ray.scattering.assign(groups, std::vector<Spectrum>(n + 1));
  std::vector<double> densities(constituents), previous(constituents);
  for (int k = 0; k <= n; ++k) {
    double t = ray.t[k];
    ray.radius[k] = glsl::RadiusAtDistance(params_, ray.r, ray.mu, t);
    medium_.Densities(ray.radius[k] - params_.bottom_radius, densities.data());
    for (int g = 0; g < groups; ++g) ray.scattering[g][k] = medium_.GroupScattering(g, densities.data());
    ray.extinction[k] = medium_.Extinction(densities.data());
    if (k > 0) {
      Spectrum tau = ray.optical_depth[k - 1];
      for (int c = 0; c < constituents; ++c) {
        tau += medium_.atmosphere().constituents[c].Extinction() *
               ExponentialTrapezoid(previous[c], densities[c], ray.t[k] - ray.t[k - 1]);
      }
      ray.optical_depth[k] = tau;
    }
    std::swap(densities, previous);
  }
  return ray;
}

Baker::SingleScattering Baker::ComputeSingleScattering(const AtmosphereParameters& grid, int ray_samples,
                                                       const OwnColumnSuns* own, const OtherColumns& other,
                                                       SingleScattering* other_out) const {
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const ChannelPlanes transmittance(transmittance_);
  const SunColumns columns(grid);
  SingleScattering result{ScatteringGridTexture(grid), ScatteringGridTexture(grid)};
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    SingleScatteringAlongRay(grid, ray_samples, ray_index % mu_size, ray_index / mu_size, columns, own, other,
                             transmittance, result, other_out);
  });
  return result;
}

void Baker::SingleScatteringAlongRay(const AtmosphereParameters& grid, int n, int y, int z, const SunColumns& columns,
                                     const OwnColumnSuns* own, const OtherColumns& other,
                                     const ChannelPlanes& transmittance, SingleScattering& out,
                                     SingleScattering* other_out) const {
  const RaySamples ray = SampleRay(grid, y, z, n);
  const SunDirections directions = RaySunDirections(columns, own, grid, y, z, other);
  const RaySingleScattering single = SingleScatteringOfRay(ray, directions.mu_s, directions.nu, transmittance);
  const auto& sums = single.sums;
  auto store = [&](const std::vector<int>& of_texel, SingleScattering& into) {
    for (int x = 0; x < int(of_texel.size()); ++x) {
      const int j = of_texel[x];
      if (j < 0) continue;
      const vec3 rayleigh(sums[0][0][j], sums[0][1][j], sums[0][2][j]);
      const vec3 mie_sum(sums[1][0][j], sums[1][1][j], sums[1][2][j]);
      into.rayleigh.Store(x, y, z, vec4(rayleigh * params_.solar_irradiance, 0.0));
      into.mie.Store(x, y, z, vec4(mie_sum * params_.solar_irradiance, 0.0));
    }
  };
  store(directions.of_texel, out);
  if (other_out) store(directions.of_other_texel, *other_out);
}

Baker::RaySingleScattering Baker::SingleScatteringOfRay(const RaySamples& ray, const std::vector<double>& sun_mu_s,
                                                        const std::vector<double>& sun_nu,
                                                        const ChannelPlanes& transmittance) const {
  const int groups = static_cast<int>(medium_.groups().size());
  const int mie = medium_.mie_group();
  const int n = static_cast<int>(ray.t.size()) - 1;
  const int count = static_cast<int>(sun_mu_s.size());

  // Per group, channel and sample, the factors shared by all directions:
  // the scattering coefficient times the view's transmittance, and the log
  // of its ratio between neighbouring samples (so that the exponential
  // trapezoid needs no logarithm per direction, and an end that underflows
  // in float still decays at its true rate), where both ends scatter.
  const std::size_t per_ray = std::size_t(groups) * 3 * (n + 1);
  std::vector<double> base_double(per_ray);  // (for the sub-intervals below, where float could underflow)
  std::vector<float> base(per_ray), log_ratio(per_ray);
  std::vector<char> has_ratio(per_ray);
  auto at = [&](int g, int c, int k) { return (std::size_t(g) * 3 + c) * (n + 1) + k; };
  std::vector<double> view_transmittance(std::size_t(3) * (n + 1));  // per channel and sample, for every group
  for (int c = 0; c < 3; ++c) {
    for (int k = 0; k <= n; ++k) view_transmittance[std::size_t(c) * (n + 1) + k] = std::exp(-ray.optical_depth[k][c]);
  }
  for (int g = 0; g < groups; ++g) {
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k <= n; ++k) {
        base_double[at(g, c, k)] = ray.scattering[g][k][c] * view_transmittance[std::size_t(c) * (n + 1) + k];
        base[at(g, c, k)] = float(base_double[at(g, c, k)]);
      }
      for (int k = 0; k < n; ++k) {
        const double a = ray.scattering[g][k][c], b = ray.scattering[g][k + 1][c];
        const bool positive = a > 0.0 && b > 0.0;
        has_ratio[at(g, c, k)] = positive;
        log_ratio[at(g, c, k)] =
            positive ? float(std::log(b / a) - (ray.optical_depth[k + 1][c] - ray.optical_depth[k][c])) : 0.0f;
      }
    }
  }
  // The table divides out the Rayleigh phase; the other groups' phases
  // (all but the Mie group's, which has its own table) are applied here.
  std::vector<std::vector<float>> phase_ratio(groups, std::vector<float>(count, 1.0f));
  std::vector<double> phase_ratio_double(std::size_t(count) * groups, 1.0);  // [direction][group]
  for (int g = 0; g < groups; ++g) {
    if (g == mie) continue;
    for (int j = 0; j < count; ++j) {
      const double nu = sun_nu[j];
      double& ratio = phase_ratio_double[std::size_t(j) * groups + g];
      ratio = medium_.groups()[g].phase.Evaluate(nu) / glsl::RayleighPhaseFunction(nu);
      phase_ratio[g][j] = float(ratio);
    }
  }

  // Per direction: the sun's optical depth, transmittance and visible
  // fraction at the previous and the current sample, and the sums.
  struct SunState {
    std::vector<float> tau[3], transmittance[3], visible;
    explicit SunState(int count) : visible(count) {
      for (int c = 0; c < 3; ++c) tau[c].resize(count), transmittance[c].resize(count);
    }
  };
  SunState previous(count), current(count);
  // The partly shadowed intervals' (interval, direction) pairs, with the
  // sunlight at their ends, and per interval, group and channel the base at
  // the ends of its sub-intervals.
  struct ShadowedPieces {
    std::vector<int> direction, interval;
    std::vector<double> mu_s, nu;
    std::vector<float> sun_start[3], sun_end[3];
  } pieces;
  std::vector<float> piece_base(std::size_t(n) * groups * 3 * (kShadowEdgeSubdivisions + 1));
  RaySingleScattering result;
  auto& sums = result.sums;
  for (auto& kind : sums) {
    for (auto& channel : kind) channel.assign(count, 0.0f);
  }
  std::vector<float> mu_s(sun_mu_s.begin(), sun_mu_s.end()), nu(sun_nu.begin(), sun_nu.end());
  std::vector<float> mu_s_k(count);
  std::vector<char> lit(count), partly_lit(count);
  std::vector<int> shadowed, thick;
  SunAtRadius sun(params_, transmittance);
  int previous_seen_from = 0;  // the previous sample's seen_from (below)
  for (int k = 0; k <= n; ++k) {
    // The sun's cosine at the sample: (r mu_s + t nu) / r_k.
    const float from_mu_s = float(ray.r / ray.radius[k]), from_nu = float(ray.t[k] / ray.radius[k]);
#pragma omp simd
    for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
    sun.SetRadius(ray.radius[k]);
    // Both callers pass the directions in order of mu_s, so those whose sun
    // is below the horizon lead. A direction whose sun is wholly hidden at
    // both ends of an interval adds nothing over it, and a hidden sun's
    // transmittance is never used (the sums keep it only where the sun is
    // visible at that end), so the loops start at the last whole vector
    // before the first direction that sees the sun: every direction keeps
    // its lane, and its value to the bit.
    const int hidden = sun.Visible(mu_s_k.data(), count, current.visible.data());
    const int seen_from = hidden / kVectorFloats * kVectorFloats;
    const int begin = std::min(seen_from, previous_seen_from);
    sun.OpticalDepth(mu_s_k.data(), seen_from, count, current.tau);
    for (int c = 0; c < 3; ++c) {
      const float* tau = current.tau[c].data();
      float* transmittance = current.transmittance[c].data();
#pragma omp simd
      for (int j = seen_from; j < count; ++j) transmittance[j] = ExpFloat(-tau[j]);
    }
    previous_seen_from = seen_from;
    if (k > 0) {
      // Fully lit, optically thin intervals: the exponential trapezoid of
      // each group's integrand, vectorised over the directions.
      const int interval = k - 1;
      const float h = float(ray.t[k] - ray.t[interval]);
      const bool thin = ray.ThinInterval(interval);
      // The rest, where any of it is lit: optically thin but partly
      // shadowed (the shadow edge crosses the interval, or the sun's disc is
      // partly hidden), or thick.
      int partly_lit_count = 0;
#pragma omp simd reduction(+ : partly_lit_count)
      for (int j = begin; j < count; ++j) {
        const bool fully_lit = previous.visible[j] == 1.0f && current.visible[j] == 1.0f;
        lit[j] = thin && fully_lit;
        partly_lit[j] = !lit[j] && (previous.visible[j] > 0.0f || current.visible[j] > 0.0f);
        partly_lit_count += partly_lit[j];
      }
      shadowed.clear(), thick.clear();
      for (int j = begin; j < count && partly_lit_count > 0; ++j) {
        if (partly_lit[j]) (thin ? shadowed : thick).push_back(j), --partly_lit_count;
      }
      for (int g = 0; g < groups; ++g) {
        for (int c = 0; c < 3; ++c) {
          const float base_a = base[at(g, c, interval)], base_b = base[at(g, c, k)];
          const float ratio = log_ratio[at(g, c, interval)];
          const bool exponential = has_ratio[at(g, c, interval)];
          const float *sun_a = previous.transmittance[c].data(), *sun_b = current.transmittance[c].data();
          const float *tau_a = previous.tau[c].data(), *tau_b = current.tau[c].data();
          const float* phase = phase_ratio[g].data();
          float* sum = sums[g == mie ? 1 : 0][c].data();
          // (Two loops: a choice between them inside one keeps it from vectorising.)
          if (exponential) {
#pragma omp simd
            for (int j = begin; j < count; ++j) {
              const float fa = base_a * sun_a[j], fb = base_b * sun_b[j];
              const float integral = ExponentialTrapezoidFloat(fa, fb, ratio - (tau_b[j] - tau_a[j]), h);
              sum[j] += lit[j] ? integral * phase[j] : 0.0f;
            }
          } else {
#pragma omp simd
            for (int j = begin; j < count; ++j) {
              const float integral = 0.5f * h * (base_a * sun_a[j] + base_b * sun_b[j]);
              sum[j] += lit[j] ? integral * phase[j] : 0.0f;
            }
          }
        }
      }
      if (!shadowed.empty()) {
        // Integrated after the last sample, all of the ray's at once.
        for (int g = 0; g < groups; ++g) {
          for (int c = 0; c < 3; ++c) {
            float* ends = &piece_base[((std::size_t(interval) * groups + g) * 3 + c) * (kShadowEdgeSubdivisions + 1)];
            if (has_ratio[at(g, c, interval)]) {
              const double step = std::exp(double(log_ratio[at(g, c, interval)]) / kShadowEdgeSubdivisions);
              double value = base_double[at(g, c, interval)];
              for (int i = 0; i <= kShadowEdgeSubdivisions; ++i, value *= step) ends[i] = float(value);
            } else {
              const float base_a = base[at(g, c, interval)], base_b = base[at(g, c, k)];
              for (int i = 0; i <= kShadowEdgeSubdivisions; ++i) {
                ends[i] = base_a + (base_b - base_a) * float(i) / kShadowEdgeSubdivisions;
              }
            }
          }
        }
        for (int j : shadowed) {
          pieces.direction.push_back(j);
          pieces.interval.push_back(interval);
          pieces.mu_s.push_back(sun_mu_s[j]), pieces.nu.push_back(sun_nu[j]);
          for (int c = 0; c < 3; ++c) {
            pieces.sun_start[c].push_back(previous.transmittance[c][j] * previous.visible[j]);
            pieces.sun_end[c].push_back(current.transmittance[c][j] * current.visible[j]);
          }
        }
      }
      for (int j : thick) {
        Spectrum rayleigh(0.0), mie_sum(0.0);
        SingleScatteringInterval(ray, interval, sun_mu_s[j], sun_nu[j],
                                 &phase_ratio_double[std::size_t(j) * groups], rayleigh, mie_sum);
        for (int c = 0; c < 3; ++c) sums[0][c][j] += float(rayleigh[c]), sums[1][c][j] += float(mie_sum[c]);
      }
    }
    std::swap(previous, current);
  }

  // The partly shadowed intervals: the sun's transmittance times its
  // visible fraction on kShadowEdgeSubdivisions sub-intervals, the
  // scattering coefficient times the view's transmittance geometric between
  // the samples (linear if an end does not scatter), and the trapezoid rule
  // on the sub-intervals; vectorised over all of the ray's such intervals
  // and directions.
  const int pair_count = static_cast<int>(pieces.direction.size());
  if (pair_count > 0) {
    constexpr int sub = kShadowEdgeSubdivisions;
    SunState start(pair_count), end(pair_count);
    for (int c = 0; c < 3; ++c) start.transmittance[c] = pieces.sun_start[c];
    std::vector<float> piece_sums[2][3], radius(pair_count), mu_s_t(pair_count), half_piece(pair_count);
    for (auto& kind : piece_sums) {
      for (auto& channel : kind) channel.assign(pair_count, 0.0f);
    }
    std::vector<double> t_start(pair_count), length(pair_count);
    // Per pair, the offset of its interval's bases in piece_base.
    std::vector<int> base_offset(pair_count);
    for (int l = 0; l < pair_count; ++l) {
      const int interval = pieces.interval[l];
      t_start[l] = ray.t[interval], length[l] = ray.t[interval + 1] - ray.t[interval];
      half_piece[l] = float(0.5 * length[l] / sub);
      base_offset[l] = interval * groups * 3 * (sub + 1);
    }
    // Per group, the phase ratio of each pair's direction, in pair order.
    std::vector<std::vector<float>> pair_phase(groups, std::vector<float>(pair_count));
    for (int g = 0; g < groups; ++g) {
      for (int l = 0; l < pair_count; ++l) pair_phase[g][l] = phase_ratio[g][pieces.direction[l]];
    }
    const double r = ray.r, r_mu = ray.r * ray.mu;
    const SunAtPoints sun_at_points(params_, transmittance);
    for (int i = 1; i <= sub; ++i) {
      if (i < sub) {
        const double fraction = double(i) / sub;
#pragma omp simd
        for (int l = 0; l < pair_count; ++l) {
          // In double: the visible fraction changes within a fraction of a
          // metre in altitude near the ground.
          const double t = t_start[l] + fraction * length[l];
          const double r_t = std::sqrt(std::max(t * t + 2.0 * r_mu * t + r * r, 0.0));
          radius[l] = float(r_t);
          mu_s_t[l] = float(std::max(-1.0, std::min((r * pieces.mu_s[l] + t * pieces.nu[l]) / r_t, 1.0)));
        }
        sun_at_points.Evaluate(radius.data(), mu_s_t.data(), pair_count, end.tau, end.visible.data());
        for (int c = 0; c < 3; ++c) {
          const float *tau = end.tau[c].data(), *visible = end.visible.data();
          float* sunlight = end.transmittance[c].data();
#pragma omp simd
          for (int l = 0; l < pair_count; ++l) sunlight[l] = ExpFloat(-tau[l]) * visible[l];
        }
      } else {
        for (int c = 0; c < 3; ++c) end.transmittance[c] = pieces.sun_end[c];
      }
      for (int g = 0; g < groups; ++g) {
        for (int c = 0; c < 3; ++c) {
          const float *sun_a = start.transmittance[c].data(), *sun_b = end.transmittance[c].data();
          const float* phase = pair_phase[g].data();
          float* sum = piece_sums[g == mie ? 1 : 0][c].data();
          const float* ends = &piece_base[(std::size_t(g) * 3 + c) * (sub + 1) + i];
#pragma omp simd
          for (int l = 0; l < pair_count; ++l) {
            const float base_a = ends[base_offset[l] - 1], base_b = ends[base_offset[l]];
            sum[l] += half_piece[l] * (base_a * sun_a[l] + base_b * sun_b[l]) * phase[l];
          }
        }
      }
      std::swap(start, end);
    }
    for (int l = 0; l < pair_count; ++l) {
      for (int kind = 0; kind < 2; ++kind) {
        for (int c = 0; c < 3; ++c) sums[kind][c][pieces.direction[l]] += piece_sums[kind][c][l];
      }
    }
  }

  return result;
}

void Baker::SingleScatteringInterval(const RaySamples& ray, int k, double mu_s, double nu, const double* phase_ratio,
                                     Spectrum& rayleigh_sum, Spectrum& mie_sum) const {
  const int groups = static_cast<int>(medium_.groups().size());
  const int mie = medium_.mie_group();
  const glsl::sampler2D transmittance{&transmittance_};
  std::vector<double> densities(medium_.constituent_count());
  std::vector<Spectrum> scattering(groups);
  // Scattered light at distance t along the ray, per kind of table.
  auto sample = [&](double t, double r_t, const Spectrum& optical_depth, const Spectrum& extinction,
                    RayIntegrand& rayleigh_out, RayIntegrand& mie_out) {
    double mu_s_t = glsl::ClampCosine((ray.r * mu_s + t * nu) / r_t);
    double visible = glsl::SunVisibleFraction(params_, r_t, mu_s_t);
    Spectrum tau = glsl::GetOpticalDepthToTopAtmosphereBoundary(params_, transmittance, r_t, mu_s_t);
    Spectrum other(0.0);
    for (int g = 0; g < groups; ++g) {
      if (g != mie) other += scattering[g] * phase_ratio[g];
    }
    Spectrum attenuation = glm::exp(-(optical_depth + tau));
    Spectrum rayleigh_source = other * visible, mie_source = mie >= 0 ? scattering[mie] * visible : Spectrum(0.0);
    rayleigh_out = RayIntegrand{rayleigh_source, optical_depth, tau, extinction, rayleigh_source * attenuation};
    mie_out = RayIntegrand{mie_source, optical_depth, tau, extinction, mie_source * attenuation};
    return visible;
  };
  auto sample_at = [&](int i, RayIntegrand& rayleigh_out, RayIntegrand& mie_out) {
    for (int g = 0; g < groups; ++g) scattering[g] = ray.scattering[g][i];
    return sample(ray.t[i], ray.radius[i], ray.optical_depth[i], ray.extinction[i], rayleigh_out, mie_out);
  };
  const double h = ray.t[k + 1] - ray.t[k];
  RayIntegrand rayleigh_a, mie_a, rayleigh_b, mie_b;
  const double visible_a = sample_at(k, rayleigh_a, mie_a), visible_b = sample_at(k + 1, rayleigh_b, mie_b);
  if (visible_a == visible_b) {
    rayleigh_sum += IntegrateInterval(rayleigh_a, rayleigh_b, h);
    mie_sum += IntegrateInterval(mie_a, mie_b, h);
    return;
  }
  // The planet's shadow edge crosses this interval: the integrand switches
  // on or off within it, so subdivide it.
  const int pieces = kShadowEdgeSubdivisions;
  const double piece = h / pieces;
  RayIntegrand previous_rayleigh = rayleigh_a, previous_mie = mie_a;
  for (int i = 1; i <= pieces; ++i) {
    RayIntegrand next_rayleigh = rayleigh_b, next_mie = mie_b;
    if (i < pieces) {
      double f = double(i) / pieces;
      double t = ray.t[k] + f * h;
      double r_t = glsl::RadiusAtDistance(params_, ray.r, ray.mu, t);
      medium_.Densities(r_t - params_.bottom_radius, densities.data());
      for (int g = 0; g < groups; ++g) scattering[g] = medium_.GroupScattering(g, densities.data());
      Spectrum optical_depth = glm::mix(ray.optical_depth[k], ray.optical_depth[k + 1], f);
      sample(t, r_t, optical_depth, medium_.Extinction(densities.data()), next_rayleigh, next_mie);
    }
    rayleigh_sum += IntegrateInterval(previous_rayleigh, next_rayleigh, piece);
    mie_sum += IntegrateInterval(previous_mie, next_mie, piece);
    previous_rayleigh = next_rayleigh, previous_mie = next_mie;
  }
}
}  // namespace skybake::detail
