// The light of an order at every texel: its scattering density integrated
// along each texel's ray.
#include "bake/baker.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include <tbb/parallel_for.h>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "bake/float_math.h"
#include "bake/grids.h"
#include "bake/sun_lookups.h"
#include "core/constants.h"
#include "core/large_buffer.h"
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

// n rounded up to whole vectors of floats.
inline int RoundUpToVector(int n) { return (n + kVectorFloats - 1) / kVectorFloats * kVectorFloats; }

// out[j] = row[index[j]] for j in [begin, end) (whole vectors), from a row
// of `size` floats; with AVX-512 and at most 32 of them, a permutation of
// the row held in two registers.
inline void LookUpInRow(const float* row, [[maybe_unused]] int size, const int* index, int begin, int end, float* out) {
#if defined(__AVX512F__)
  if (size <= 2 * kVectorFloats) {
    const __mmask16 low_mask = size >= kVectorFloats ? __mmask16(0xffff) : __mmask16((1u << size) - 1u);
    const __mmask16 high_mask = size <= kVectorFloats       ? __mmask16(0)
                                : size >= 2 * kVectorFloats ? __mmask16(0xffff)
                                                            : __mmask16((1u << (size - kVectorFloats)) - 1u);
    const __m512 low = _mm512_maskz_loadu_ps(low_mask, row),
                 high = _mm512_maskz_loadu_ps(high_mask, row + kVectorFloats);
    for (int j = begin; j < end; j += kVectorFloats) {
      _mm512_storeu_ps(out + j, _mm512_permutex2var_ps(low, _mm512_loadu_si512(index + j), high));
    }
    return;
  }
#endif
#pragma omp simd
  for (int j = begin; j < end; ++j) out[j] = row[index[j]];
}

// A ray's sun directions (RaySunDirections) with the nu slices of the
// density grid around their nu. With `by_slice`, grouped by the slice below
// their nu, so that every direction of a group reads J's nu rows `slice`
// and `next_slice` (as JRows's permutations need): within a group in order
// of mu_s, each group padded to whole vectors with copies of its last
// direction. Else one group of them all in their order (of mu_s).
struct DirectionsBySlice {
  struct Group {
    int slice, next_slice;  // the group's, where grouped by slice (else -1)
    int begin, end;         // [begin, end): its positions
  };
  std::vector<Group> groups;
  std::vector<int> of_texel;  // per texel column x of the grid, its direction's position
  // Per position (slice and next_slice only where not grouped by slice:
  // a group's directions share its own):
  std::vector<float> mu_s, nu;
  std::vector<int> slice, next_slice;
  std::vector<float> nu_weight;  // of next_slice

  DirectionsBySlice(const SunDirections& directions, const AtmosphereParameters& grid, bool by_slice) {
    const int nu_size = grid.scattering_nu_size;
    const int distinct = by_slice ? *std::max_element(directions.of_texel.begin(), directions.of_texel.end()) + 1
                                  : static_cast<int>(directions.nu.size());
    const int group_count = by_slice ? nu_size : 1;
    std::vector<int> slice_of(distinct), position(distinct);
    std::vector<float> weight(distinct);
    // The directions of each group in their order, members[group_start[g]]
    // onward (a counting sort by group).
    std::vector<int> group_start(group_count + 1, 0), members(distinct);
    for (int j = 0; j < distinct; ++j) {
      const double nu_coord = glsl::ScatteringUnitNu(directions.nu[j]) * (nu_size - 1);
      slice_of[j] = std::min(int(std::floor(nu_coord)), nu_size - 1);
      ++group_start[(by_slice ? slice_of[j] : 0) + 1];
      weight[j] = float(nu_coord - slice_of[j]);
    }
    for (int g = 0; g < group_count; ++g) group_start[g + 1] += group_start[g];
    std::vector<int> next_member(group_start.begin(), group_start.end() - 1);
    for (int j = 0; j < distinct; ++j) members[next_member[by_slice ? slice_of[j] : 0]++] = j;
    // At most a vector's padding per group.
    const std::size_t most = std::size_t(distinct) + std::size_t(nu_size) * (kVectorFloats - 1);
    mu_s.reserve(most), nu.reserve(most), nu_weight.reserve(most);
    if (!by_slice) slice.reserve(most), next_slice.reserve(most);
    groups.reserve(group_count);
    for (int g = 0; g < group_count; ++g) {
      const int first = group_start[g], size = group_start[g + 1] - first;
      if (size == 0) continue;
      const int group_slice = by_slice ? slice_of[members[first]] : -1;
      Group group{group_slice, by_slice ? std::min(group_slice + 1, nu_size - 1) : -1, count(), 0};
      for (int m = 0; m < size || count() % kVectorFloats != 0; ++m) {
        const int j = members[first + std::min(m, size - 1)];
        if (m < size) position[j] = count();
        mu_s.push_back(float(directions.mu_s[j])), nu.push_back(float(directions.nu[j]));
        if (!by_slice) slice.push_back(slice_of[j]), next_slice.push_back(std::min(slice_of[j] + 1, nu_size - 1));
        nu_weight.push_back(weight[j]);
      }
      group.end = count();
      groups.push_back(group);
    }
    of_texel.reserve(directions.of_texel.size());
    for (int texel : directions.of_texel) of_texel.push_back(position[texel]);
  }
  int count() const { return static_cast<int>(mu_s.size()); }
};

// J per channel in rows along mu_s: of a density texture, per (r, mu) row
// and channel, one row per nu slice padded to whole vectors (Rows); and of
// a sample, those of its four (r, mu) rows blended, and the lookups of the
// ray's directions in them (Accumulate).
class JRows {
 public:
  JRows(int mu_s_size, int nu_size)
      : mu_s_size_(mu_s_size),
        nu_size_(nu_size),
        stride_(std::max(kRegisterRow, RoundUpToVector(mu_s_size))),
        values_(PerTexelRow(), 0.0f) {}

  // Whether Accumulate's lookups are permutations of rows in registers,
  // which needs the directions grouped by nu slice (DirectionsBySlice).
  bool PermutesRows() const {
#if defined(__AVX512F__)
    return stride_ == kRegisterRow;
#else
    return false;
#endif
  }

  // Floats per (r, mu) row of a texture: 3 channels, nu_size rows of stride_.
  std::size_t PerTexelRow() const { return std::size_t(3) * nu_size_ * stride_; }

  // The texture's rgb in rows: per (r, mu) row, PerTexelRow() floats, the
  // padding zero. Into `rows_out`, which a gather of every order reuses: its
  // padding stays zero and every other value is overwritten.
  void Rows(const Texture& density, LargeBuffer<float>* rows_out) const {
    LargeBuffer<float>& rows = *rows_out;
    rows.resize(std::size_t(density.height) * density.depth * PerTexelRow(), 0.0f);
    ForEachRow(density, [&](int row, std::size_t first, std::size_t) {
      float* out = &rows[row * PerTexelRow()];
      for (int c = 0; c < 3; ++c) {
        for (int s = 0; s < nu_size_; ++s) {
          const float* texels = &density.texels[first + std::size_t(4) * s * mu_s_size_ + c];
          float* row_out = out + (std::size_t(c) * nu_size_ + s) * stride_;
          for (int i = 0; i < mu_s_size_; ++i) row_out[i] = texels[4 * i];
        }
      }
    });
  }

  // The sample's rows: the four (r, mu) rows' (of Rows) blended by their weights.
  void Set(const float* t00, const float* t10, const float* t01, const float* t11, float w00, float w10, float w01,
           float w11) {
    const int size = static_cast<int>(values_.size());
    float* values = values_.data();
#pragma omp simd
    for (int i = 0; i < size; ++i) values[i] = w00 * t00[i] + w10 * t10[i] + w01 * t01[i] + w11 * t11[i];
  }

  // For the directions j of a group of `directions`, channel c: J between
  // the mu_s columns left[j] and left[j] + 1 at weight_a[j] in the nu row of
  // j's slice and at weight_b[j] in the row of its next slice, blended
  // between the rows by j's nu weight, into value[j]; sum[j] += w value[j].
  void Accumulate(int c, const DirectionsBySlice& directions, const DirectionsBySlice::Group& group, const int* left,
                  const float* weight_a, const float* weight_b, float w, float* value, float* sum) const {
    const float* nu_weight = directions.nu_weight.data();
#if defined(__AVX512F__)
    if (PermutesRows()) {
      // Each row in two registers: a tap is one permutation of them.
      const float* row_a = Row(values_, c, group.slice);
      const float* row_b = Row(values_, c, group.next_slice);
      const __m512 a_low = _mm512_loadu_ps(row_a), a_high = _mm512_loadu_ps(row_a + 16);
      const __m512 b_low = _mm512_loadu_ps(row_b), b_high = _mm512_loadu_ps(row_b + 16);
      const __m512 weight = _mm512_set1_ps(w);
      const __m512i one = _mm512_set1_epi32(1);
      for (int j = group.begin; j < group.end; j += kVectorFloats) {
        const __m512i column = _mm512_loadu_si512(left + j), next_column = _mm512_add_epi32(column, one);
        const __m512 left_a = _mm512_permutex2var_ps(a_low, column, a_high);
        const __m512 left_b = _mm512_permutex2var_ps(b_low, column, b_high);
        const __m512 along_a =
            _mm512_fmadd_ps(_mm512_loadu_ps(weight_a + j),
                            _mm512_sub_ps(_mm512_permutex2var_ps(a_low, next_column, a_high), left_a), left_a);
        const __m512 along_b =
            _mm512_fmadd_ps(_mm512_loadu_ps(weight_b + j),
                            _mm512_sub_ps(_mm512_permutex2var_ps(b_low, next_column, b_high), left_b), left_b);
        const __m512 blend = _mm512_fmadd_ps(_mm512_loadu_ps(nu_weight + j), _mm512_sub_ps(along_b, along_a), along_a);
        _mm512_storeu_ps(value + j, blend);
        _mm512_storeu_ps(sum + j, _mm512_fmadd_ps(weight, blend, _mm512_loadu_ps(sum + j)));
      }
      return;
    }
#endif
    // Elsewhere each direction reads its rows by index (the same arithmetic).
    const float* values = Row(values_, c, 0);
    const int *slice = directions.slice.data(), *next_slice = directions.next_slice.data();
    const int stride = stride_;
#pragma omp simd
    for (int j = group.begin; j < group.end; ++j) {
      const int a = slice[j] * stride + left[j], b = next_slice[j] * stride + left[j];
      const float along_a = values[a] + weight_a[j] * (values[a + 1] - values[a]);
      const float along_b = values[b] + weight_b[j] * (values[b + 1] - values[b]);
      value[j] = along_a + nu_weight[j] * (along_b - along_a);
      sum[j] += w * value[j];
    }
  }

 private:
  // A row that fits two 512-bit registers.
  static constexpr int kRegisterRow = 2 * kVectorFloats;
  const float* Row(const std::vector<float>& rows, int c, int s) const {
    return &rows[(std::size_t(c) * nu_size_ + s) * stride_];
  }
  int mu_s_size_, nu_size_, stride_;
  std::vector<float> values_;
};
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
      glsl::LowestSunLogFall(glsl::LogLight(column_value(0)), glsl::LogLight(column_value(1)), columns.mu_s[0],
                             columns.mu_s[1], slope, curvature);
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

// What GatherAlongRays needs of each ray of a table's grid whatever the
// density it gathers: the samples at which J is read, with their taps in
// the density grid's (r, mu) rows, the weights of J there and the
// optically thick intervals. Every order gathers along the same rays, so it
// is built once (PlanGather).
struct Baker::GatherPlan {
  struct ThickInterval {
    int k, c;
    double albedo_a, albedo_b;
  };
  // A sample with a non-zero weight (or a thick interval's end): its taps
  // in the density grid's r and mu rows, interpolated once for all of the
  // ray's texels (the texture's r and mu interpolation), and the sun's
  // cosine there for a direction (mu_s, nu): mu_s from_mu_s + nu from_nu.
  struct Sample {
    int k;
    int row00, row10, row01, row11;
    float w00, w10, w01, w11;
    int nearest_row;  // the (r, mu) row nearest it (MuSFall's)
    float from_mu_s, from_nu;
  };
  struct Ray {
    std::vector<Sample> samples;
    std::vector<glm::vec3> weight;  // per sample k and channel, of J
    std::vector<ThickInterval> thick_intervals;
    std::vector<Spectrum> optical_depth;  // the view's, per sample k (where there are thick intervals)
  };
  AtmosphereParameters grid, density_grid;
  const OwnColumnSuns* own_suns = nullptr;  // of grid, where it has a split
  int samples_per_ray = 0;                  // intervals per ray
  // Per ray index z * mu_size + y; they depend on the grid's r and mu rows
  // alone, and a plan for the same rows and other columns shares them
  // (PlanGatherForColumns).
  std::shared_ptr<std::vector<Ray>> rays;
  // The gathered order's J in JRows's layout (JRows::Rows): kept with the
  // plan so that every order's gather writes into pages already touched,
  // instead of faulting in a fresh buffer on the calling thread.
  LargeBuffer<float> density_rows;
};

std::shared_ptr<Baker::GatherPlan> Baker::PlanGather(const AtmosphereParameters& grid, const OwnColumnSuns* own,
                                                     const AtmosphereParameters& density_grid) const {
  auto plan = std::make_shared<GatherPlan>();
  plan->grid = grid, plan->density_grid = density_grid, plan->own_suns = own;
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const int density_height = density_grid.scattering_mu_size, density_depth = density_grid.scattering_r_size;
  const int n = std::max(std::min(settings_.ray_samples, 32), settings_.ray_samples / 2);
  plan->samples_per_ray = n;
  plan->rays = std::make_shared<std::vector<GatherPlan::Ray>>(std::size_t(r_size) * mu_size);
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    const int z = ray_index / mu_size, y = ray_index % mu_size;
    GatherPlan::Ray& out = (*plan->rays)[ray_index];
    const RaySamples ray = SampleRay(grid, y, z, n);
    // The integrand is J times the scattering coefficient times the view's
    // transmittance. Over optically thin intervals J varies slowly and is
    // taken as linear between samples, the rest as exponential, which makes
    // the integral a weighted sum of J at the samples with weights shared by
    // all the ray's texels. Over thick ones (more than one optical depth) J
    // can fall by orders of magnitude (into a fog) and the integrand is
    // taken as exponential per unit of the view's optical depth, per texel
    // (IntegrateOverOpticalDepth).
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
          out.thick_intervals.push_back({k, c, albedo_a, albedo_b});
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
    out.weight.assign(weight.begin(), weight.end());
    out.samples.reserve(n + 1);
    if (!out.thick_intervals.empty()) out.optical_depth = ray.optical_depth;
    for (int k = 0; k <= n; ++k) {
      needed[k] = needed[k] || weight[k] != Spectrum(0.0);
      if (!needed[k]) continue;
      const double mu_k = glsl::CosineAtDistance(ray.r, ray.mu, ray.t[k], ray.radius[k]);
      const glsl::vec4 uvwz =
          glsl::GetScatteringTextureUvwzFromRMuMuSNu(density_grid, ray.radius[k], mu_k, 1.0, 1.0, ray.intersects_ground);
      int y0, y1, z0, z1;
      double fy, fz;
      glsl::detail::LinearTaps(uvwz.z, density_height, y0, y1, fy);
      glsl::detail::LinearTaps(uvwz.w, density_depth, z0, z1, fz);
      auto row = [&](int y, int z) { return z * density_height + y; };
      out.samples.push_back({k, row(y0, z0), row(y1, z0), row(y0, z1), row(y1, z1), float((1 - fy) * (1 - fz)),
                             float(fy * (1 - fz)), float((1 - fy) * fz), float(fy * fz),
                             row(fy < 0.5 ? y0 : y1, fz < 0.5 ? z0 : z1), float(ray.r / ray.radius[k]),
                             float(ray.t[k] / ray.radius[k])});
    }
  });
  return plan;
}

std::shared_ptr<Baker::GatherPlan> Baker::PlanGatherForColumns(const GatherPlan& plan, const AtmosphereParameters& grid,
                                                               const OwnColumnSuns* own) const {
  auto same_rays = std::make_shared<GatherPlan>();
  same_rays->grid = grid, same_rays->density_grid = plan.density_grid, same_rays->own_suns = own;
  same_rays->samples_per_ray = plan.samples_per_ray;
  same_rays->rays = plan.rays;
  return same_rays;
}

void Baker::GatherAlongRays(GatherPlan& plan, const Texture& density, const MuSFall* fall, Texture* result_out) const {
  const AtmosphereParameters &grid = plan.grid, &density_grid = plan.density_grid;
  // Every texel is written below, so the texture's memory is reused as it is.
  Texture& result = *result_out;
  SizeForScatteringGrid(grid, &result);
  const int mu_size = grid.scattering_mu_size, r_size = grid.scattering_r_size;
  const int density_mu_s_size = density_grid.scattering_mu_s_size, density_nu_size = density_grid.scattering_nu_size;
  const int n = plan.samples_per_ray;
  // J in rows along mu_s per channel and nu slice (JRows).
  const JRows layout(density_mu_s_size, density_nu_size);
  const std::size_t per_row = layout.PerTexelRow();
  layout.Rows(density, &plan.density_rows);
  const LargeBuffer<float>& density_rows = plan.density_rows;
  const SunColumns columns(grid);
  const MuSCoordinate mu_s_coordinate(density_grid);
  const float lowest_mu_s = float(density_grid.scattering_mu_s_min);
  auto rows_at = [&](int row) { return &density_rows[std::size_t(row) * per_row]; };
  tbb::parallel_for(0, r_size * mu_size, [&](int ray_index) {
    const int z = ray_index / mu_size, y = ray_index % mu_size;
    const GatherPlan::Ray& ray = (*plan.rays)[ray_index];
    // The ray's sun directions, grouped by the nu slice below them where
    // JRows's lookups along mu_s are permutations of rows held in registers
    // (each vector of directions then reads the same two nu rows of J);
    // within a group in order of mu_s (DirectionsBySlice). Formed per
    // order: kept in the plan they would take more memory than all the
    // rest of it (docs/benchmark.md).
    JRows rows(density_mu_s_size, density_nu_size);
    const DirectionsBySlice by_slice(RaySunDirections(columns, plan.own_suns, grid, y, z), density_grid,
                                     rows.PermutesRows());
    const int count = by_slice.count();
    const std::vector<float>&mu_s = by_slice.mu_s, &nu = by_slice.nu, &nu_weight = by_slice.nu_weight;
    std::vector<float> mu_s_k(count), mu_s_weight(count), values(count);
    std::vector<int> mu_s_left(count);
    std::vector<float> sums[3], source;  // source: J per sample, channel and direction, for thick intervals
    for (auto& sum : sums) sum.assign(count, 0.0f);
    if (!ray.thick_intervals.empty()) source.assign(std::size_t(n + 1) * 3 * count, 0.0f);
    const bool shaped = fall != nullptr && fall->falling_columns > 0;
    std::vector<float> fall_weight_a(shaped ? count : 0), fall_weight_b(shaped ? count : 0);
    std::vector<int> falling_column(shaped ? count : 0);
    std::vector<float> ratio_a(shaped ? count : 0), ratio_b(shaped ? count : 0);
    std::vector<float> inverse_a(shaped ? count : 0), inverse_b(shaped ? count : 0);
    // Per channel and direction, the fall of J below the lowest column at
    // the sample (1 where the sun is above it): exp(d (slope + d curvature))
    // with d = mu_s - mu_s_min < 0, slope and curvature blended between the
    // nu rows. Within a group only the first directions (to its entry in
    // below_end) can have the sun below the lowest column.
    std::vector<float> below_factor[3];
    for (auto& factor : below_factor) factor.resize(fall ? count : 0);
    std::vector<int> below_end(by_slice.groups.size());
    for (const GatherPlan::Sample& sample : ray.samples) {
      const int k = sample.k;
      // J at the sample's (r, mu) for every (nu, mu_s) texel.
      rows.Set(rows_at(sample.row00), rows_at(sample.row10), rows_at(sample.row01), rows_at(sample.row11), sample.w00,
               sample.w10, sample.w01, sample.w11);
      const float from_mu_s = sample.from_mu_s, from_nu = sample.from_nu;
      // MuSFall's offsets of the row nearest the sample.
      const std::size_t fall_row = fall ? std::size_t(sample.nearest_row) * density_nu_size * fall->falling_columns : 0;
      const std::size_t lowest_row = std::size_t(sample.nearest_row) * density_nu_size * 3;
#pragma omp simd
      for (int j = 0; j < count; ++j) mu_s_k[j] = ClampFloat(mu_s[j] * from_mu_s + nu[j] * from_nu, -1.0f, 1.0f);
      mu_s_coordinate.Taps(mu_s_k.data(), count, mu_s_left.data(), mu_s_weight.data());
      for (std::size_t g = 0; g < by_slice.groups.size(); ++g) {
        const DirectionsBySlice::Group& group = by_slice.groups[g];
        // The sun's cosine at the sample, (mu_s r + nu t) / r_k, is at least
        // mu_s r / r_k - t / r_k: from the first direction of the group this
        // returns on, every direction's sun at the sample is at or above
        // `cosine`.
        auto surely_at_or_above = [&](float cosine) {
          return static_cast<int>(
              std::lower_bound(mu_s.begin() + group.begin, mu_s.begin() + group.end, (cosine + from_nu) / from_mu_s) -
              mu_s.begin());
        };
        // Just past the last direction whose sun at the sample is below the
        // lowest column (none without `fall`).
        int last_below = group.begin - 1;
        const int bound = fall ? surely_at_or_above(lowest_mu_s) : group.begin;
#pragma omp simd reduction(max : last_below)
        for (int j = group.begin; j < bound; ++j) last_below = std::max(last_below, mu_s_k[j] < lowest_mu_s ? j : -1);
        int end = last_below + 1;
        // Rounded up to a whole vector: past the last sun below the lowest
        // column the factor is exp(0) = 1, which changes nothing.
        if (end > group.begin) end = std::min(group.end, RoundUpToVector(end - group.begin) + group.begin);
        below_end[g] = end;
        // The slope and curvature blended between each direction's nu rows
        // (for a group of one slice, the same two rows throughout).
        auto below_factors = [&](auto slice_of, auto next_slice_of) {
          for (int c = 0; c < 3 && end > group.begin; ++c) {
            const float* slope = &fall->lowest_log_slope[lowest_row + c];
            const float* curvature = &fall->lowest_log_curvature[lowest_row + c];
            float* factor = below_factor[c].data();
#pragma omp simd
            for (int j = group.begin; j < end; ++j) {
              const int a = 3 * slice_of(j), b = 3 * next_slice_of(j);
              const float t = nu_weight[j], d = std::min(mu_s_k[j] - lowest_mu_s, 0.0f);
              const float slope_j = slope[a] + t * (slope[b] - slope[a]);
              const float curvature_j = curvature[a] + t * (curvature[b] - curvature[a]);
              factor[j] = ExpFloat(d * (slope_j + d * curvature_j));
            }
          }
        };
        if (group.slice >= 0) {
          below_factors([&](int) { return group.slice; }, [&](int) { return group.next_slice; });
        } else {
          const int *slice = by_slice.slice.data(), *next_slice = by_slice.next_slice.data();
          below_factors([&](int j) { return slice[j]; }, [&](int j) { return next_slice[j]; });
        }
        if (shaped) {
          // The weights of the right columns of the two nu rows, following
          // the fall (the same for the three channels). From `falling_end`
          // on (rounded up to a whole vector, so that each direction keeps
          // its lane) no direction's sun is below the first column that
          // does not fall (plus a margin far above the float position's
          // rounding), and FallWeight would return mu_s_weight.
          const float* log_ratio = &fall->log_ratio[fall_row];
          const float* inverse = &fall->inverse_ratio_minus_one[fall_row];
          const int falling = fall->falling_columns;
          int falling_end = surely_at_or_above(fall->steady_mu_s + kSteadyMargin);
          falling_end = std::min(group.end, group.begin + RoundUpToVector(falling_end - group.begin));
          std::copy(mu_s_weight.begin() + falling_end, mu_s_weight.begin() + group.end,
                    fall_weight_a.begin() + falling_end);
          std::copy(mu_s_weight.begin() + falling_end, mu_s_weight.begin() + group.end,
                    fall_weight_b.begin() + falling_end);
          // Per direction, the ln of the ratio and 1 / (ratio - 1) of the
          // pair of columns it lies between in each of its nu rows.
#pragma omp simd
          for (int j = group.begin; j < falling_end; ++j) {
            falling_column[j] = mu_s_left[j] < falling ? mu_s_left[j] : falling - 1;  // any, when it does not fall
          }
          if (group.slice >= 0) {
            // One pair of rows for the whole group.
            const int a = group.slice * falling, b = group.next_slice * falling;
            LookUpInRow(log_ratio + a, falling, falling_column.data(), group.begin, falling_end, ratio_a.data());
            LookUpInRow(log_ratio + b, falling, falling_column.data(), group.begin, falling_end, ratio_b.data());
            LookUpInRow(inverse + a, falling, falling_column.data(), group.begin, falling_end, inverse_a.data());
            LookUpInRow(inverse + b, falling, falling_column.data(), group.begin, falling_end, inverse_b.data());
          } else {
            const int *slice = by_slice.slice.data(), *next_slice = by_slice.next_slice.data();
#pragma omp simd
            for (int j = group.begin; j < falling_end; ++j) {
              const int a = slice[j] * falling + falling_column[j], b = next_slice[j] * falling + falling_column[j];
              ratio_a[j] = log_ratio[a], ratio_b[j] = log_ratio[b], inverse_a[j] = inverse[a],
              inverse_b[j] = inverse[b];
            }
          }
#pragma omp simd
          for (int j = group.begin; j < falling_end; ++j) {
            const bool falls = mu_s_left[j] < falling;
            fall_weight_a[j] = FallWeight(mu_s_weight[j], ratio_a[j], falls ? inverse_a[j] : 0.0f);
            fall_weight_b[j] = FallWeight(mu_s_weight[j], ratio_b[j], falls ? inverse_b[j] : 0.0f);
          }
        }
      }
      // The weights of the right columns of the two nu rows: mu_s_weight,
      // or with a fall, those that follow it.
      const float* weight_a = shaped ? fall_weight_a.data() : mu_s_weight.data();
      const float* weight_b = shaped ? fall_weight_b.data() : mu_s_weight.data();
      for (int c = 0; c < 3; ++c) {
        const float w = ray.weight[k][c];
        float* sum = sums[c].data();
        float* value = source.empty() ? values.data() : &source[(std::size_t(k) * 3 + c) * count];
        const float* factor = below_factor[c].data();
        for (std::size_t g = 0; g < by_slice.groups.size(); ++g) {
          rows.Accumulate(c, by_slice, by_slice.groups[g], mu_s_left.data(), weight_a, weight_b, w, value, sum);
          // Below the lowest column the lookup read the lowest column's J
          // (its weight clamped to 0); it falls from there.
#pragma omp simd
          for (int j = by_slice.groups[g].begin; j < below_end[g]; ++j) {
            sum[j] += w * value[j] * (factor[j] - 1.0f);
            value[j] *= factor[j];
          }
        }
      }
    }
    std::vector<Spectrum> directions_sum(count);
    for (int j = 0; j < count; ++j) {
      Spectrum sum(sums[0][j], sums[1][j], sums[2][j]);
      for (const GatherPlan::ThickInterval& interval : ray.thick_intervals) {
        const int k = interval.k, c = interval.c;
        const double value_a = source[(std::size_t(k) * 3 + c) * count + j] * interval.albedo_a;
        const double value_b = source[(std::size_t(k + 1) * 3 + c) * count + j] * interval.albedo_b;
        sum[c] += IntegrateOverOpticalDepth(value_a, value_b, 0.0, 0.0, ray.optical_depth[k][c],
                                            ray.optical_depth[k + 1][c]);
      }
      directions_sum[j] = sum;
    }
    for (int x = 0; x < int(by_slice.of_texel.size()); ++x) {
      result.Store(x, y, z, vec4(directions_sum[by_slice.of_texel[x]], 0.0));
    }
  });
}

}  // namespace skybake::detail
