// The light of an order at every texel: its scattering density integrated
// along each texel's ray.
#include "bake/baker.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/float_math.h"
#include "bake/grids.h"
#include "bake/sun_lookups.h"
#include "core/constants.h"
#include "shaders_runtime/runtime.h"

namespace skybake::detail {

namespace {
// The largest ln of the ratio of J between neighbouring columns that
// MuSFall keeps (a fall by 5e8).
constexpr float kLargestLogRatio = 20.0f;
// Margin in mu_s (about 0.005 texels of the columns around the horizon) by
// which a sun is taken to be above the first column that does not fall.
constexpr float kSteadyMargin = 1e-4f;
// The weight of the right column at position f in [0, 1] (in texels from
// the left one) for a pair whose J falls by exp(log_ratio) from right to
// left: (exp(f L) - 1) / (exp(L) - 1), which reads J = a exp(f L) exactly
// when J is exponential between the columns (b = a exp(L)) and is linear in
// a and b. Without a fall (inverse 0), f.
inline float FallWeight(float f, float log_ratio, float inverse_ratio_minus_one) {
  return inverse_ratio_minus_one == 0.0f ? f : (ExpFloat(f * log_ratio) - 1.0f) * inverse_ratio_minus_one;
}
}  // namespace

Baker::MuSFall Baker::MuSFallOf(const Texture& density, bool between_columns) const {
  const SunColumns columns(atmosphere_grid_);
  const int mu_s_size = atmosphere_grid_.scattering_mu_s_size, nu_size = atmosphere_grid_.scattering_nu_size;
  MuSFall fall;
  while (between_columns && fall.falling_columns < mu_s_size - 1 && columns.mu_s[fall.falling_columns] < 0.0) {
    ++fall.falling_columns;
  }
  fall.steady_mu_s = float(columns.mu_s[fall.falling_columns]);
  const int columns_per_row = nu_size * fall.falling_columns;
  fall.log_ratio.assign(std::size_t(density.height) * density.depth * columns_per_row, 0.0f);
  fall.inverse_ratio_minus_one.assign(fall.log_ratio.size(), 0.0f);
  fall.lowest_log_slope.assign(std::size_t(density.height) * density.depth * nu_size * 3, 0.0f);
  fall.lowest_log_curvature.assign(fall.lowest_log_slope.size(), 0.0f);
  ForEachRow(density, [&](int row, std::size_t first, std::size_t) {
    for (int nu = 0; nu < nu_size; ++nu) {
      // Below the grid's lowest sun: the runtime's continuation of the two
      // lowest columns (LowestSunLogFall), per channel.
      const float* lowest = &density.texels[first + std::size_t(4) * nu * mu_s_size];
      auto column_value = [&](int column) {
        return glsl::vec4(lowest[4 * column], lowest[4 * column + 1], lowest[4 * column + 2], 0.0);
      };
      glsl::vec4 slope, curvature;
      glsl::LowestSunLogFall(column_value(0), column_value(1), columns.mu_s[0], columns.mu_s[1], slope, curvature);
      for (int c = 0; c < 3; ++c) {
        const std::size_t i = (std::size_t(row) * nu_size + nu) * 3 + c;
        fall.lowest_log_slope[i] = float(slope[c]);
        fall.lowest_log_curvature[i] = float(curvature[c]);
      }
      for (int column = 0; column < fall.falling_columns; ++column) {
        // J summed over the channels: one fall for the three.
        const float* a = &density.texels[first + std::size_t(4) * (nu * mu_s_size + column)];
        const double sum_a = double(a[0]) + a[1] + a[2], sum_b = double(a[4]) + a[5] + a[6];
        if (!(sum_a > 0.0 && sum_b > 0.0)) continue;
        const double log_ratio = std::min(std::log(sum_b / sum_a), double(kLargestLogRatio));
        if (!(log_ratio > 1e-3)) continue;
        const std::size_t i = std::size_t(row) * columns_per_row + nu * fall.falling_columns + column;
        fall.log_ratio[i] = float(log_ratio);
        fall.inverse_ratio_minus_one[i] = float(1.0 / std::expm1(log_ratio));
      }
    }
  });
  return fall;
}

Texture Baker::GatherAlongRays(const AtmosphereParameters& grid, const Texture& density,
                               const AtmosphereParameters& density_grid, const MuSFall* fall) const {
  Texture result = ScatteringGridTexture(grid);
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const int density_mu_s_size = density_grid.scattering_mu_s_size, density_nu_size = density_grid.scattering_nu_size;
  const int plane_width = density.width;  // density nu * mu_s
  const SunColumns columns(grid);
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    const int z = ray_index / mu_size, y = ray_index % mu_size;
    const int n = std::max(std::min(settings_.ray_samples, 32), settings_.ray_samples / 2);
    const RaySamples ray = SampleRay(grid, y, z, n);
    // The integrand is J times the scattering coefficient times the view's
    // transmittance. Over optically thin intervals J varies slowly and is
    // taken as linear between samples, the rest as exponential, which makes
    // the integral a weighted sum of J at the samples with weights shared by
    // all the ray's texels. Over thick ones (more than one optical depth) J
    // can fall by orders of magnitude (into a fog) and the integrand is
    // taken as exponential per unit of the view's optical depth, per texel
    // (IntegrateOverOpticalDepth).
    struct ThickInterval {
      int k, c;
      double albedo_a, albedo_b;
    };
    std::vector<ThickInterval> thick_intervals;
    std::vector<Spectrum> weight(n + 1, Spectrum(0.0));
    std::vector<Spectrum> scattering(n + 1, Spectrum(0.0));
    std::vector<bool> needed(n + 1, false);  // J is looked up there
    for (int k = 0; k <= n; ++k) {
      for (const std::vector<Spectrum>& group : ray.scattering) scattering[k] += group[k];
    }
    for (int k = 0; k < n; ++k) {
      for (int c = 0; c < 3; ++c) {
        const double view_depth = ray.optical_depth[k + 1][c] - ray.optical_depth[k][c];
        const double extinction_a = ray.extinction[k][c], extinction_b = ray.extinction[k + 1][c];
        if (view_depth > 1.0 && (extinction_a > 0.0 || extinction_b > 0.0)) {
          // Albedo per unit optical depth; a vacuum end takes the other's.
          const double albedo_a =
              extinction_a > 0.0 ? scattering[k][c] / extinction_a : scattering[k + 1][c] / extinction_b;
          const double albedo_b = extinction_b > 0.0 ? scattering[k + 1][c] / extinction_b : albedo_a;
          thick_intervals.push_back({k, c, albedo_a, albedo_b});
          needed[k] = needed[k + 1] = true;
          continue;
        }
        const double factor_a = scattering[k][c], factor_b = scattering[k + 1][c];
        const double lambda = factor_a > 0.0 && factor_b > 0.0 ? std::log(factor_b / factor_a) - view_depth
                                                                : std::numeric_limits<double>::quiet_NaN();
        const std::pair<double, double> w = LinearTimesExponentialWeights(
            factor_a * std::exp(-ray.optical_depth[k][c]), factor_b * std::exp(-ray.optical_depth[k + 1][c]), lambda,
            ray.t[k + 1] - ray.t[k]);
        weight[k][c] += w.first;
        weight[k + 1][c] += w.second;
      }
    }
    // J at each sample's (r, mu) for every (nu, mu_s) texel of the density
    // grid: the texture's r and mu interpolation, done once per sample.
    std::vector<int> samples;  // those with a non-zero weight
    std::vector<std::size_t> fall_rows;  // per sample, MuSFall's row nearest it
    std::vector<std::size_t> lowest_rows;  // and that row's offset in lowest_log_slope and _curvature
    std::vector<float> planes;
    planes.reserve(std::size_t(n + 1) * 4 * plane_width);
    for (int k = 0; k <= n; ++k) {
      needed[k] = needed[k] || weight[k] != Spectrum(0.0);
      if (!needed[k]) continue;
      const double mu_k = glsl::CosineAtDistance(ray.r, ray.mu, ray.t[k], ray.radius[k]);
      const glsl::vec4 uvwz =
          glsl::GetScatteringTextureUvwzFromRMuMuSNu(density_grid, ray.radius[k], mu_k, 1.0, 1.0, ray.intersects_ground);
      int y0, y1, z0, z1;
      double fy, fz;
      glsl::detail::LinearTaps(uvwz.z, density.height, y0, y1, fy);
      glsl::detail::LinearTaps(uvwz.w, density.depth, z0, z1, fz);
      const float* t00 = &density.texels[density.Index(0, y0, z0)];
      const float* t10 = &density.texels[density.Index(0, y1, z0)];
      const float* t01 = &density.texels[density.Index(0, y0, z1)];
      const float* t11 = &density.texels[density.Index(0, y1, z1)];
      const float w00 = float((1 - fy) * (1 - fz)), w10 = float(fy * (1 - fz)), w01 = float((1 - fy) * fz),
                  w11 = float(fy * fz);
      const std::size_t offset = planes.size();
      planes.resize(offset + std::size_t(4) * plane_width);
      float* plane = &planes[offset];
      for (int i = 0; i < 4 * plane_width; ++i) plane[i] = w00 * t00[i] + w10 * t10[i] + w01 * t01[i] + w11 * t11[i];
      samples.push_back(k);
      if (fall) {
        const std::size_t row = std::size_t(fz < 0.5 ? z0 : z1) * density.height + (fy < 0.5 ? y0 : y1);
        fall_rows.push_back(row * density_nu_size * fall->falling_columns);
        lowest_rows.push_back(row * density_nu_size * 3);
      }
    }

    // Per distinct sun direction of the ray: its nu taps in the density
    // grid (nu is the same all along the ray), then per sample its mu_s
    // taps and J, vectorised over the directions.
    const SunDirections directions = RaySunDirections(columns, ray.mu);
    const int count = static_cast<int>(directions.nu.size());
    std::vector<float> mu_s(directions.mu_s.begin(), directions.mu_s.end()), nu(directions.nu.begin(), directions.nu.end());
    std::vector<int> nu_slice0(count), nu_slice1(count);
    std::vector<int> nu_row0(count), nu_row1(count);  // offsets of the nu rows in a plane
    std::vector<int> fall_row0(count), fall_row1(count);  // and in a row of MuSFall
    std::vector<float> nu_weight(count);
    for (int j = 0; j < count; ++j) {
      const double nu_coord = glsl::ScatteringUnitNu(directions.nu[j]) * (density_nu_size - 1);
      const int nu0 = std::min(int(std::floor(nu_coord)), density_nu_size - 1), nu1 = std::min(nu0 + 1, density_nu_size - 1);
      nu_slice0[j] = nu0, nu_slice1[j] = nu1;
      nu_row0[j] = 4 * nu0 * density_mu_s_size, nu_row1[j] = 4 * nu1 * density_mu_s_size;
      if (fall) fall_row0[j] = nu0 * fall->falling_columns, fall_row1[j] = nu1 * fall->falling_columns;
      nu_weight[j] = float(nu_coord - nu0);
    }
    const MuSCoordinate mu_s_coordinate(density_grid);
    const float lowest_mu_s = float(density_grid.scattering_mu_s_min);
    std::vector<Spectrum> directions_sum(count);
    std::vector<float> mu_s_k(count), mu_s_weight(count), values(count);
    std::vector<int> mu_s_left(count);
    std::vector<float> sums[3], source;  // source: J per sample, channel and direction, for thick intervals
    for (auto& sum : sums) sum.assign(count, 0.0f);
    if (!thick_intervals.empty()) source.assign(std::size_t(n + 1) * 3 * count, 0.0f);
    const bool shaped = fall != nullptr && fall->falling_columns > 0;
    std::vector<float> fall_weight_a(shaped ? count : 0), fall_weight_b(shaped ? count : 0);
    // Per channel and direction, the fall of J below the lowest column at
    // the sample (1 where the sun is above it): exp(d (slope + d curvature))
    // with d = mu_s - mu_s_min < 0, slope and curvature blended between the
    // nu rows. The directions come in order of mu_s (RaySunDirections), and
    // only the first `below_end` can have the sun below the lowest column.
    std::vector<float> below_factor[3];
    for (auto& factor : below_factor) factor.resize(fall ? count : 0);
    int below_end = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const int k = samples[i];
      const float* plane = &planes[i * std::size_t(4) * plane_width];
      const float from_mu_s = float(ray.r / ray.radius[k]), from_nu = float(ray.t[k] / ray.radius[k]);
#pragma omp simd
      for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
      mu_s_coordinate.Taps(mu_s_k.data(), count, mu_s_left.data(), mu_s_weight.data());
      // The sun's cosine at the sample, (mu_s r + nu t) / r_k, is at least
      // mu_s r / r_k - t / r_k: from the first direction this returns on,
      // every direction's sun at the sample is at or above `cosine`.
      auto surely_at_or_above = [&](float cosine) {
        return static_cast<int>(std::lower_bound(mu_s.begin(), mu_s.end(), (cosine + from_nu) / from_mu_s) -
                                mu_s.begin());
      };
      below_end = fall ? surely_at_or_above(lowest_mu_s) : 0;
      int below_count = 0;
#pragma omp simd reduction(+ : below_count)
      for (int j = 0; j < below_end; ++j) below_count += mu_s_k[j] < lowest_mu_s ? 1 : 0;
      if (below_count == 0) below_end = 0;
      while (below_end > 0 && !(mu_s_k[below_end - 1] < lowest_mu_s)) --below_end;
      for (int c = 0; c < 3 && below_end > 0; ++c) {
        const float* slope = &fall->lowest_log_slope[lowest_rows[i] + c];
        const float* curvature = &fall->lowest_log_curvature[lowest_rows[i] + c];
        float* factor = below_factor[c].data();
#pragma omp simd
        for (int j = 0; j < below_end; ++j) {
          const int a = 3 * nu_slice0[j], b = 3 * nu_slice1[j];
          const float t = nu_weight[j], d = std::min(mu_s_k[j] - lowest_mu_s, 0.0f);
          const float slope_j = slope[a] + t * (slope[b] - slope[a]);
          const float curvature_j = curvature[a] + t * (curvature[b] - curvature[a]);
          factor[j] = ExpFloat(d * (slope_j + d * curvature_j));
        }
      }
      // The weights of the right columns of the two nu rows: mu_s_weight,
      // or with a fall, weights that follow it (the same for the three
      // channels).
      const float* weight_a = mu_s_weight.data();
      const float* weight_b = mu_s_weight.data();
      if (shaped) {
        const float* log_ratio = &fall->log_ratio[fall_rows[i]];
        const float* inverse = &fall->inverse_ratio_minus_one[fall_rows[i]];
        const int falling = fall->falling_columns;
        // From `falling_end` on (rounded up to a whole vector, so that each
        // direction keeps its lane) no direction's sun is below the first
        // column that does not fall (plus a margin far above the float
        // position's rounding), and FallWeight would return mu_s_weight.
        int falling_end = surely_at_or_above(fall->steady_mu_s + kSteadyMargin);
        falling_end = std::min(count, (falling_end + kVectorFloats - 1) / kVectorFloats * kVectorFloats);
        std::copy(mu_s_weight.begin() + falling_end, mu_s_weight.end(), fall_weight_a.begin() + falling_end);
        std::copy(mu_s_weight.begin() + falling_end, mu_s_weight.end(), fall_weight_b.begin() + falling_end);
#pragma omp simd
        for (int j = 0; j < falling_end; ++j) {
          const int left = mu_s_left[j];
          const int column = left < falling ? left : falling - 1;  // any, when the pair does not fall
          const int a = fall_row0[j] + column, b = fall_row1[j] + column;
          const float inverse_a = left < falling ? inverse[a] : 0.0f, inverse_b = left < falling ? inverse[b] : 0.0f;
          fall_weight_a[j] = FallWeight(mu_s_weight[j], log_ratio[a], inverse_a);
          fall_weight_b[j] = FallWeight(mu_s_weight[j], log_ratio[b], inverse_b);
        }
        weight_a = fall_weight_a.data(), weight_b = fall_weight_b.data();
      }
      for (int c = 0; c < 3; ++c) {
        const float w = float(weight[k][c]);
        float* sum = sums[c].data();
        float* value = source.empty() ? values.data() : &source[(std::size_t(k) * 3 + c) * count];
#pragma omp simd
        for (int j = 0; j < count; ++j) {
          const int a = nu_row0[j] + 4 * mu_s_left[j] + c, b = nu_row1[j] + 4 * mu_s_left[j] + c;
          const float along_a = plane[a] + weight_a[j] * (plane[a + 4] - plane[a]);
          const float along_b = plane[b] + weight_b[j] * (plane[b + 4] - plane[b]);
          value[j] = along_a + nu_weight[j] * (along_b - along_a);
          sum[j] += w * value[j];
        }
        // Below the lowest column the loop above read the lowest column's J
        // (its weight clamped to 0); it falls from there.
        const float* factor = below_factor[c].data();
#pragma omp simd
        for (int j = 0; j < below_end; ++j) {
          sum[j] += w * value[j] * (factor[j] - 1.0f);
          value[j] *= factor[j];
        }
      }
    }
    for (int j = 0; j < count; ++j) {
      Spectrum sum(sums[0][j], sums[1][j], sums[2][j]);
      for (const ThickInterval& interval : thick_intervals) {
        const int k = interval.k, c = interval.c;
        const double value_a = source[(std::size_t(k) * 3 + c) * count + j] * interval.albedo_a;
        const double value_b = source[(std::size_t(k + 1) * 3 + c) * count + j] * interval.albedo_b;
        sum[c] += IntegrateOverOpticalDepth(value_a, value_b, 0.0, 0.0, ray.optical_depth[k][c],
                                            ray.optical_depth[k + 1][c]);
      }
      directions_sum[j] = sum;
    }
    for (int x = 0; x < int(directions.of_texel.size()); ++x) {
      result.Store(x, y, z, vec4(directions_sum[directions.of_texel[x]], 0.0));
    }
  });
  return result;
}

}  // namespace skybake::detail
