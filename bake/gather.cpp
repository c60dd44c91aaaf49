// The light of an order at every texel: its scattering density integrated
// along each texel's ray.
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
Texture Baker::GatherAlongRays(const AtmosphereParameters& grid, const Texture& density,
                               const AtmosphereParameters& density_grid) const {
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
    }

    // Per distinct sun direction of the ray: its nu taps in the density
    // grid (nu is the same all along the ray), then per sample its mu_s
    // taps and J, vectorised over the directions.
    const SunDirections directions = RaySunDirections(columns, ray.mu);
    const int count = static_cast<int>(directions.nu.size());
    std::vector<float> mu_s(directions.mu_s.begin(), directions.mu_s.end()), nu(directions.nu.begin(), directions.nu.end());
    std::vector<int> nu_row0(count), nu_row1(count);  // offsets of the nu rows in a plane
    std::vector<float> nu_weight(count);
    for (int j = 0; j < count; ++j) {
      const double nu_coord = glsl::ScatteringUnitNu(directions.nu[j]) * (density_nu_size - 1);
      const int nu0 = std::min(int(std::floor(nu_coord)), density_nu_size - 1), nu1 = std::min(nu0 + 1, density_nu_size - 1);
      nu_row0[j] = 4 * nu0 * density_mu_s_size, nu_row1[j] = 4 * nu1 * density_mu_s_size;
      nu_weight[j] = float(nu_coord - nu0);
    }
    const MuSCoordinate mu_s_coordinate(density_grid);
    std::vector<Spectrum> directions_sum(count);
    std::vector<float> mu_s_k(count), mu_s_weight(count), values(count);
    std::vector<int> mu_s_left(count);
    std::vector<float> sums[3], source;  // source: J per sample, channel and direction, for thick intervals
    for (auto& sum : sums) sum.assign(count, 0.0f);
    if (!thick_intervals.empty()) source.assign(std::size_t(n + 1) * 3 * count, 0.0f);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      const int k = samples[i];
      const float* plane = &planes[i * std::size_t(4) * plane_width];
      const float from_mu_s = float(ray.r / ray.radius[k]), from_nu = float(ray.t[k] / ray.radius[k]);
#pragma omp simd
      for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
      mu_s_coordinate.Taps(mu_s_k.data(), count, mu_s_left.data(), mu_s_weight.data());
      for (int c = 0; c < 3; ++c) {
        const float w = float(weight[k][c]);
        float* sum = sums[c].data();
        float* value = source.empty() ? values.data() : &source[(std::size_t(k) * 3 + c) * count];
#pragma omp simd
        for (int j = 0; j < count; ++j) {
          const int a = nu_row0[j] + 4 * mu_s_left[j] + c, b = nu_row1[j] + 4 * mu_s_left[j] + c;
          const float f = mu_s_weight[j];
          const float along_a = plane[a] + f * (plane[a + 4] - plane[a]);
          const float along_b = plane[b] + f * (plane[b + 4] - plane[b]);
          value[j] = along_a + nu_weight[j] * (along_b - along_a);
          sum[j] += w * value[j];
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
