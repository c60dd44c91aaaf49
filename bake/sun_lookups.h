// The sun seen from the samples of a ray, for all of the ray's sun
// directions at once: the directions of a scattering grid's texels, and the
// transmittance table's optical depth and the visible fraction of the sun's
// disc, in float and vectorised.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "bake/bake.h"
#include "bake/detail.h"
#include "bake/float_math.h"
#include "bake/own_column_suns.h"
#include "shaders_runtime/primitives.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace skybake::detail {

// Per texel column x of a scattering grid, the sun's cosine mu_s and the
// nu of the column's slice: they depend on x alone.
struct SunColumns {
  std::vector<double> mu_s, grid_nu;
  int mu_s_size = 0, nu_size = 0;
  explicit SunColumns(const AtmosphereParameters& grid)
      : mu_s_size(grid.scattering_mu_s_size), nu_size(grid.scattering_nu_size) {
    for (int x = 0; x < mu_s_size * nu_size; ++x) {
      const ScatteringTexel texel = GetScatteringTexel(grid, x, 0, 0);
      mu_s.push_back(texel.mu_s), grid_nu.push_back(texel.grid_nu);
    }
  }
};

// Columns a ray's single scattering is also wanted at: [first, end) of
// another grid with the same r and mu rows and nu slices and no split (the
// orders' grid where the table's columns below its split are each ray's:
// Baker::Run).
struct OtherColumns {
  const SunColumns* columns = nullptr;
  int first = 0, end = 0;
};

// The distinct sun directions of the ray (mu index y, r index z) of a
// scattering grid: its (mu_s, nu) texels, nu clamped as GetScatteringTexel
// clamps it to the range that mu and mu_s allow, with the slices that
// clamping gave the same direction merged, as their integrals are the same;
// and those of `other`'s columns; in order of mu_s (the lowest sun first),
// padded to whole vectors. The columns from the grid's split up are
// `columns`' (the same for every ray); those below it the ray's own,
// `own`'s (null where the grid has no split).
struct SunDirections {
  std::vector<double> mu_s, nu;     // per direction
  std::vector<int> of_texel;        // texel x -> direction
  std::vector<int> of_other_texel;  // texel x of the other grid -> direction (-1: none)
};

inline SunDirections RaySunDirections(const SunColumns& columns, const OwnColumnSuns* own,
                                      const AtmosphereParameters& grid, int y, int z, const OtherColumns& other = {}) {
  SunDirections directions;
  const double mu = GetScatteringSliceTexel(grid, 0, y, z).mu;
  // The directions of one grid's columns [first, end), into `of_texel`.
  auto add = [&](const SunColumns& grid_columns, int split, int first, int end, std::vector<int>& of_texel) {
    of_texel.assign(grid_columns.mu_s.size(), -1);
    for (int mu_s_index = first; mu_s_index < end; ++mu_s_index) {
      for (int nu_index = 0; nu_index < grid_columns.nu_size; ++nu_index) {
        const int x = nu_index * grid_columns.mu_s_size + mu_s_index;
        const double mu_s = mu_s_index < split ? own->MuS(x, y, z) : grid_columns.mu_s[x];
        const double nu = ClampedNu(grid_columns.grid_nu[x], mu, mu_s);
        if (nu_index == 0 || nu != directions.nu.back() || mu_s != directions.mu_s.back()) {
          directions.mu_s.push_back(mu_s);
          directions.nu.push_back(nu);
        }
        of_texel[x] = static_cast<int>(directions.nu.size()) - 1;
      }
    }
  };
  add(columns, grid.scattering_mu_s_split, 0, columns.mu_s_size, directions.of_texel);
  if (other.columns) add(*other.columns, 0, other.first, other.end, directions.of_other_texel);
  if (grid.scattering_mu_s_split > 0 || other.columns) {
    // The rays' own columns interleave in mu_s across slices: sorted.
    std::vector<int> order(directions.mu_s.size()), position(order.size());
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = static_cast<int>(j);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return directions.mu_s[a] < directions.mu_s[b]; });
    SunDirections sorted;
    for (std::size_t j = 0; j < order.size(); ++j) {
      position[order[j]] = static_cast<int>(j);
      sorted.mu_s.push_back(directions.mu_s[order[j]]);
      sorted.nu.push_back(directions.nu[order[j]]);
    }
    for (std::vector<int>* of : {&directions.of_texel, &directions.of_other_texel}) {
      for (int& texel : *of) texel = texel < 0 ? texel : position[texel];
    }
    sorted.of_texel = std::move(directions.of_texel);
    sorted.of_other_texel = std::move(directions.of_other_texel);
    directions = std::move(sorted);
  }
  // Padded with copies of the last direction to whole vectors, so that the
  // loops over the directions leave no scalar remainder (no texel reads the
  // copies).
  while (directions.mu_s.size() % kVectorFloats != 0) {
    directions.mu_s.push_back(directions.mu_s.back());
    directions.nu.push_back(directions.nu.back());
  }
  return directions;
}

// The number of a grid's low-sun columns (mu_s < LOW_SUN_MU_S), which
// come first.
inline int LowSunColumnCount(const SunColumns& columns) {
  int count = 0;
  while (count < columns.mu_s_size && columns.mu_s[count] < glsl::LOW_SUN_MU_S) ++count;
  return count;
}

// The rgb of a 2D texture as one plane per channel (gathers of one channel).
struct ChannelPlanes {
  int width = 0, height = 0;
  std::vector<float> channel[3];
  explicit ChannelPlanes(const Texture& texture) : width(texture.width), height(texture.height) {
    for (int c = 0; c < 3; ++c) {
      channel[c].resize(std::size_t(width) * height);
      for (std::size_t i = 0; i < channel[c].size(); ++i) channel[c][i] = texture.texels[4 * i + c];
    }
  }
};

// The transmittance table's x in texels for a ray from radius r (with
// c = top^2 - r^2, d_min = top - r and scale = (width - 1) / (d_max - d_min))
// in direction mu: GetTransmittanceTextureUvFromRMu's x, with its linear map
// from distance to texels hoisted into d_min and scale.
inline float TransmittanceTableX(float r, float c, float d_min, float scale, float mu, float last) {
  return ClampFloat((glsl_float::DistanceToSphereFromInside(r * mu, c) - d_min) * scale, 0.0f, last);
}

class SunAtRadius {
 public:
  SunAtRadius(const AtmosphereParameters& params, const ChannelPlanes& transmittance)
      : params_(params), transmittance_(transmittance) {
    // Padded so that a window that starts at any texel stays inside.
    for (auto& row : row_) row.resize(transmittance.width + kWindow, 0.0f);
  }

  void SetRadius(double r) {
    const AtmosphereParameters& p = params_;
    r = std::clamp(r, p.bottom_radius, p.top_radius);
    const double horizon_at_top = glsl::HorizonDistanceAtTop(p), rho = glsl::HorizonDistance(p, r);
    const double d_min = p.top_radius - r, d_max = rho + horizon_at_top;
    r_ = float(r);
    c_ = float((p.top_radius - r) * (p.top_radius + r));
    d_min_ = float(d_min);
    scale_ = d_max > d_min ? float((transmittance_.width - 1) / (d_max - d_min)) : 0.0f;
    int y0, y1;
    double fy;
    glsl::detail::LinearTaps(glsl::GetTextureCoordFromUnitRange(rho / horizon_at_top, transmittance_.height),
                             transmittance_.height, y0, y1, fy);
    // The two rows around the radius, blended once for all directions.
    const int width = transmittance_.width;
    const float weight = float(fy);
    for (int channel = 0; channel < 3; ++channel) {
      const float* a = transmittance_.channel[channel].data() + std::size_t(y0) * width;
      const float* b = transmittance_.channel[channel].data() + std::size_t(y1) * width;
      float* row = row_[channel].data();
#pragma omp simd
      for (int x = 0; x < width; ++x) row[x] = a[x] + weight * (b[x] - a[x]);
    }
    const double sin_horizon = p.bottom_radius / r;
    horizon_cosine_ = float(glsl::HorizonZenithCosine(p.bottom_radius, r));
    half_disc_ = float(sin_horizon * p.sun_angular_radius);
  }

  // The visible fraction of the sun's disc into visible[j], for `count` sun
  // cosines; returns how many of the first ones see none of it.
  int Visible(const float* mu_s, int count, float* visible) const {
    const float horizon = horizon_cosine_, half_disc = half_disc_;
#pragma omp simd
    for (int j = 0; j < count; ++j) visible[j] = glsl_float::SunVisibleFractionAboveHorizon(mu_s[j], horizon, half_disc);
    int hidden = 0;
    while (hidden < count && visible[hidden] == 0.0f) ++hidden;
    return hidden;
  }

  // The optical depth per channel into tau[c][j], for the sun cosines j in
  // [begin, count), begin a whole number of vectors.
  void OpticalDepth(const float* mu_s, int begin, int count, std::vector<float> (&tau)[3]) {
    const float r = r_, c = c_, d_min = d_min_, scale = scale_;
    const float last = float(transmittance_.width - 1);
    const int last_left = transmittance_.width - 2;
    if (int(left_.size()) < count) left_.resize(count), weight_.resize(count);
    int* left = left_.data();
    float* weight = weight_.data();
#pragma omp simd
    for (int j = begin; j < count; ++j) {
      const float x = TransmittanceTableX(r, c, d_min, scale, mu_s[j], last);
      left[j] = std::min(static_cast<int>(x), last_left);
      weight[j] = x - float(left[j]);
    }
    int j = begin;
#if defined(__AVX512F__)
    // Where a vector of directions' taps (left and right) lie within
    // kWindow texels of the row, it reads them by permutations of that
    // window held in registers (two per tap, one where the taps lie within
    // half of it) instead of a gather per channel and tap: the directions
    // come in order of mu_s, and 70 % of the default bake's vectors fit.
    // value + weight * (next - value) is the arithmetic of LookUp, to the
    // bit. Wider vectors, and the rest, gather.
    for (; j + kVectorFloats <= count; j += kVectorFloats) {
      const __m512i taps = _mm512_loadu_si512(left + j);
      const int lowest = LowestLane(taps), highest = -LowestLane(_mm512_sub_epi32(_mm512_setzero_si512(), taps));
      if (highest + 1 - lowest >= kWindow) {
        LookUp(j, j + kVectorFloats, tau);
        continue;
      }
      const __m512i index = _mm512_sub_epi32(taps, _mm512_set1_epi32(lowest));
      const __m512i next_index = _mm512_add_epi32(index, _mm512_set1_epi32(1));
      const bool half_window = highest + 1 - lowest < kWindow / 2;
      const __mmask16 upper = _mm512_cmpge_epi32_mask(index, _mm512_set1_epi32(kWindow / 2));
      const __mmask16 next_upper = _mm512_cmpge_epi32_mask(next_index, _mm512_set1_epi32(kWindow / 2));
      const __m512 w = _mm512_loadu_ps(weight + j);
      for (int channel = 0; channel < 3; ++channel) {
        const float* window = row_[channel].data() + lowest;
        const __m512 r0 = _mm512_loadu_ps(window), r1 = _mm512_loadu_ps(window + kVectorFloats);
        __m512 value = _mm512_permutex2var_ps(r0, index, r1), next = _mm512_permutex2var_ps(r0, next_index, r1);
        if (!half_window) {
          const __m512 r2 = _mm512_loadu_ps(window + 2 * kVectorFloats),
                       r3 = _mm512_loadu_ps(window + 3 * kVectorFloats);
          value = _mm512_mask_blend_ps(upper, value, _mm512_permutex2var_ps(r2, index, r3));
          next = _mm512_mask_blend_ps(next_upper, next, _mm512_permutex2var_ps(r2, next_index, r3));
        }
        _mm512_storeu_ps(tau[channel].data() + j, _mm512_fmadd_ps(w, _mm512_sub_ps(next, value), value));
      }
    }
#endif
    LookUp(j, count, tau);
  }

 private:
  // The texels of the row that OpticalDepth permutes: four 512-bit registers.
  static constexpr int kWindow = 4 * kVectorFloats;

#if defined(__AVX512F__)
  // The least of a vector's 16 integers, by halving. (The masked forms,
  // with every lane set, name a source for the lanes they keep; the plain
  // ones' undefined source draws a false warning from GCC 12.)
  static int LowestLane(__m512i v) {
    const __mmask16 all = 0xffff;
    v = _mm512_mask_min_epi32(v, all, v, _mm512_mask_shuffle_i32x4(v, all, v, v, _MM_SHUFFLE(1, 0, 3, 2)));
    v = _mm512_mask_min_epi32(v, all, v, _mm512_mask_shuffle_i32x4(v, all, v, v, _MM_SHUFFLE(2, 3, 0, 1)));
    v = _mm512_mask_min_epi32(v, all, v, _mm512_mask_shuffle_epi32(v, all, v, _MM_PERM_BADC));
    v = _mm512_mask_min_epi32(v, all, v, _mm512_mask_shuffle_epi32(v, all, v, _MM_PERM_CDAB));
    return _mm512_cvtsi512_si32(v);
  }
#endif

  // The optical depth per channel for the directions in [begin, end), from
  // their taps in left_ and weight_.
  void LookUp(int begin, int end, std::vector<float> (&tau)[3]) const {
    const int* left = left_.data();
    const float* weight = weight_.data();
    for (int channel = 0; channel < 3; ++channel) {
      const float* row = row_[channel].data();
      float* out = tau[channel].data();
#pragma omp simd
      for (int j = begin; j < end; ++j) out[j] = row[left[j]] + weight[j] * (row[left[j] + 1] - row[left[j]]);
    }
  }

  const AtmosphereParameters& params_;
  const ChannelPlanes& transmittance_;  // optical depth
  std::vector<int> left_;               // per direction: the left tap along x
  std::vector<float> weight_;           // and the right one's weight
  std::vector<float> row_[3];           // per channel, the table interpolated to the radius
  float r_ = 0.0f, c_ = 0.0f, d_min_ = 0.0f, scale_ = 0.0f, horizon_cosine_ = 0.0f, half_disc_ = 0.0f;
};

// The same for points at different radii (each its own bilinear lookup):
// for the sub-intervals of the partly shadowed intervals of a ray, batched.
class SunAtPoints {
 public:
  SunAtPoints(const AtmosphereParameters& params, const ChannelPlanes& transmittance)
      : params_(params), transmittance_(transmittance) {}

  // For `count` points at radii r[l] with sun cosines mu_s[l]: the optical
  // depth per channel into tau[c][l] and the visible fraction into visible[l].
  void Evaluate(const float* r_in, const float* mu_s, int count, std::vector<float> (&tau)[3], float* visible) const {
    const AtmosphereParameters& p = params_;
    const float bottom = float(p.bottom_radius), top = float(p.top_radius);
    const float horizon_at_top = float(glsl::HorizonDistanceAtTop(p)), angular_radius = float(p.sun_angular_radius);
    const int width = transmittance_.width, height = transmittance_.height;
    const float last_x = float(width - 1), last_y = float(height - 1);
    const int last_left = width - 2, last_low = std::max(height - 2, 0);
    const float *plane0 = transmittance_.channel[0].data(), *plane1 = transmittance_.channel[1].data(),
                *plane2 = transmittance_.channel[2].data();
    float *tau0 = tau[0].data(), *tau1 = tau[1].data(), *tau2 = tau[2].data();
#pragma omp simd
    for (int l = 0; l < count; ++l) {
      const float r = ClampFloat(r_in[l], bottom, top);
      const float rho = glsl_float::DistanceToHorizon(bottom, r);
      const float d_min = top - r, d_max = rho + horizon_at_top;
      const float scale = d_max > d_min ? last_x / (d_max - d_min) : 0.0f;
      const float x = TransmittanceTableX(r, (top - r) * (top + r), d_min, scale, mu_s[l], last_x);
      const float y = ClampFloat(rho / horizon_at_top * last_y, 0.0f, last_y);
      const int i = std::min(static_cast<int>(x), last_left), k = std::min(static_cast<int>(y), last_low);
      const float fx = x - float(i), fy = y - float(k);
      const int t00 = k * width + i, t10 = t00 + 1, t01 = std::min(k + 1, height - 1) * width + i, t11 = t01 + 1;
      const float a0 = plane0[t00] + fx * (plane0[t10] - plane0[t00]), b0 = plane0[t01] + fx * (plane0[t11] - plane0[t01]);
      const float a1 = plane1[t00] + fx * (plane1[t10] - plane1[t00]), b1 = plane1[t01] + fx * (plane1[t11] - plane1[t01]);
      const float a2 = plane2[t00] + fx * (plane2[t10] - plane2[t00]), b2 = plane2[t01] + fx * (plane2[t11] - plane2[t01]);
      tau0[l] = a0 + fy * (b0 - a0), tau1[l] = a1 + fy * (b1 - a1), tau2[l] = a2 + fy * (b2 - a2);
      visible[l] = glsl_float::SunVisibleFractionAboveHorizon(mu_s[l], glsl_float::HorizonZenithCosine(bottom, r),
                                                              bottom / r * angular_radius);
    }
  }

 private:
  const AtmosphereParameters& params_;
  const ChannelPlanes& transmittance_;  // optical depth
};

// glsl::GetScatteringTextureUMuS in float, as the left tap and weight of the
// linear interpolation along mu_s (vectorisable): the same primitives, with
// the linear maps of the distance to its unit range and of the unit range to
// texels hoisted into constants.
class MuSCoordinate {
 public:
  explicit MuSCoordinate(const AtmosphereParameters& grid) {
    const double top = grid.top_radius, bottom = grid.bottom_radius;
    const double d_min = top - bottom, d_max = glsl::HorizonDistanceAtTop(grid);
    bottom_ = float(bottom), c_ = float((top - bottom) * (top + bottom)), d_min_ = float(d_min);
    inverse_span_ = float(1.0 / (d_max - d_min)), inverse_a_ = float(glsl::GetScatteringSunAxis(grid).inverse_A);
    last_ = float(grid.scattering_mu_s_size - 1), last_left_ = grid.scattering_mu_s_size - 2;
    scale_ = float((grid.scattering_mu_s_size - 1) / glsl::GetScatteringUnitMuS(grid, grid.scattering_mu_s_max));
  }
  // For `count` sun cosines: the position along the mu_s axis in texels
  // (in [0, size - 1]) split into a left tap (whose right neighbour exists)
  // and the weight of the right one.
  void Taps(const float* mu_s, int count, int* left, float* weight) const {
    const float bottom = bottom_, c = c_, d_min = d_min_, inverse_span = inverse_span_, inverse_a = inverse_a_;
    const float last = last_, scale = scale_;
    const int last_left = last_left_;
#pragma omp simd
    for (int j = 0; j < count; ++j) {
      const float d = glsl_float::DistanceToSphereFromInside(bottom * mu_s[j], c);
      const float a = (d - d_min) * inverse_span;
      const float position = ClampFloat(glsl_float::ScatteringUnitMuSFromDistance(a, inverse_a) * scale, 0.0f, last);
      const int i = std::min(static_cast<int>(position), last_left);
      left[j] = i;
      weight[j] = position - float(i);
    }
  }

 private:
  float bottom_ = 0.0f, c_ = 0.0f, d_min_ = 0.0f, inverse_span_ = 0.0f, inverse_a_ = 0.0f, last_ = 0.0f, scale_ = 0.0f;
  int last_left_ = 0;
};
}  // namespace skybake::detail
