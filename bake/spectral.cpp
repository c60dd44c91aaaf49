#include "bake/spectral.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "bake/colour.h"
#include "bake/medium.h"
#include "bake/own_column_suns.h"
#include "core/constants.h"
#include "core/errors.h"
#include "shaders_runtime/runtime.h"

namespace skybake {

std::vector<double> SpectralWavelengths(int count) {
  if (count < kWavelengthCount) {
    throw InputError("a spectral bake needs at least 3 wavelengths, not " + std::to_string(count));
  }
  if (count > kMaxSpectralWavelengths) {
    throw InputError("a spectral bake takes at most " + std::to_string(kMaxSpectralWavelengths) +
                     " wavelengths (one per 5 nm of the colour-matching data), not " + std::to_string(count));
  }
  std::vector<double> wavelengths;
  for (int i = 0; i < count; ++i) {
    wavelengths.push_back(kSpectralFirstNm + (kSpectralLastNm - kSpectralFirstNm) * double(i) / double(count - 1));
  }
  return wavelengths;
}

SpectralBatches MakeSpectralBatches(const std::vector<double>& wavelengths_nm, SpectralHigherOrders higher_orders) {
  SpectralBatches batches;
  batches.wavelengths_nm = wavelengths_nm;
  const int count = static_cast<int>(wavelengths_nm.size());
  const bool interpolated = higher_orders == SpectralHigherOrders::kInterpolated && count > kWavelengthCount;
  // The order of the wavelengths in the batches: interpolated, the nearest
  // to each anchor first (each taken once), then the rest.
  std::vector<int> order;
  if (interpolated) {
    for (double anchor : kInterpolationAnchorsNm) {
      int nearest = -1;
      for (int i = 0; i < count; ++i) {
        if (std::find(order.begin(), order.end(), i) != order.end()) continue;
        if (nearest < 0 || std::abs(wavelengths_nm[i] - anchor) < std::abs(wavelengths_nm[nearest] - anchor))
          nearest = i;
      }
      order.push_back(nearest);
    }
    std::sort(order.begin(), order.end());
  }
  for (int i = 0; i < count; ++i) {
    if (std::find(order.begin(), order.end(), i) == order.end()) order.push_back(i);
  }
  const std::vector<glm::dvec3> weights = XyzWeights(wavelengths_nm);
  for (int first = 0; first < count; first += kWavelengthCount) {
    Spectrum nm(0.0);
    glm::dmat3 to_xyz(0.0);
    std::array<int, kWavelengthCount> index{};
    for (int c = 0; c < kWavelengthCount; ++c) {
      const bool repeat = first + c >= count;
      const int i = order[repeat ? count - 1 : first + c];
      nm[c] = wavelengths_nm[i];
      index[c] = repeat ? -1 : i;
      if (!repeat) to_xyz[c] = kLuminousEfficacyLmPerW * weights[i];
    }
    batches.batch_wavelengths_nm.push_back(nm);
    batches.wavelength_index.push_back(index);
    batches.to_xyz.push_back(to_xyz);
  }
  batches.higher_order_batches = interpolated ? 1 : batches.size();
  return batches;
}

SpectralHigherOrders ParseSpectralHigherOrders(const std::string& name) {
  if (name == "interpolated") return SpectralHigherOrders::kInterpolated;
  if (name == "exact") return SpectralHigherOrders::kExact;
  throw InputError("spectral higher orders: '" + name + "' is not interpolated or exact");
}

const char* ToString(SpectralHigherOrders higher_orders) {
  return higher_orders == SpectralHigherOrders::kExact ? "exact" : "interpolated";
}

std::vector<int> SpectralBatches::HigherOrderWavelengths() const {
  std::vector<int> computed;
  for (std::size_t b = 0; b < higher_order_batches; ++b) {
    for (int i : wavelength_index[b]) {
      if (i >= 0) computed.push_back(i);
    }
  }
  std::sort(computed.begin(), computed.end());
  return computed;
}

HigherOrderInterpolation MakeHigherOrderInterpolation(const std::vector<double>& wavelengths_nm,
                                                      const std::vector<int>& computed,
                                                      const std::vector<double>& ground_scattering,
                                                      const std::vector<double>& absorption_depth) {
  const int n = static_cast<int>(wavelengths_nm.size()), k = static_cast<int>(computed.size());
  HigherOrderInterpolation result;
  // Linear interpolation in wavelength between the computed wavelengths,
  // held beyond them: weights[i][j].
  std::vector<std::vector<double>> linear(n, std::vector<double>(k, 0.0));
  for (int i = 0; i < n; ++i) {
    const double w = wavelengths_nm[i];
    int j = 0;
    while (j + 1 < k && wavelengths_nm[computed[j + 1]] <= w) ++j;
    if (j + 1 == k || w <= wavelengths_nm[computed[j]]) {
      linear[i][j] = 1.0;
    } else {
      const double t =
          (w - wavelengths_nm[computed[j]]) / (wavelengths_nm[computed[j + 1]] - wavelengths_nm[computed[j]]);
      linear[i][j] = 1.0 - t, linear[i][j + 1] = t;
    }
  }
  // The basis functions at every wavelength, and those the computed
  // wavelengths tell apart (Gram-Schmidt on their values there, a function
  // left out where less than 1e-6 of it is new).
  auto basis = [&](int i) {
    return std::array<double, 3>{1.0, ground_scattering[i] > 0.0 ? std::log(ground_scattering[i]) : 0.0,
                                 absorption_depth[i]};
  };
  std::vector<int> kept;
  std::vector<std::vector<double>> orthonormal;  // per kept function, over the computed wavelengths
  for (int f = 0; f < 3; ++f) {
    std::vector<double> v(k);
    for (int j = 0; j < k; ++j) v[j] = basis(computed[j])[f];
    double norm0 = 0.0;
    for (double x : v) norm0 += x * x;
    for (const std::vector<double>& q : orthonormal) {
      double dot = 0.0;
      for (int j = 0; j < k; ++j) dot += q[j] * v[j];
      for (int j = 0; j < k; ++j) v[j] -= dot * q[j];
    }
    double norm = 0.0;
    for (double x : v) norm += x * x;
    if (!(norm > 1e-12 * norm0)) continue;
    for (double& x : v) x /= std::sqrt(norm);
    orthonormal.push_back(v);
    kept.push_back(f);
  }
  // The least-squares fit of the kept functions to values l_j at the
  // computed wavelengths is P l, P = (B^T B)^-1 B^T with B[j][f] the kept
  // functions there; at wavelength i it is b_i . P l. Solved per function
  // column by Gauss-Jordan elimination on B^T B (at most 3 x 3).
  const int m = static_cast<int>(kept.size());
  std::vector<std::vector<double>> b(k, std::vector<double>(m));
  for (int j = 0; j < k; ++j) {
    for (int f = 0; f < m; ++f) b[j][f] = basis(computed[j])[kept[f]];
  }
  std::vector<std::vector<double>> p(m, std::vector<double>(k, 0.0));  // P, m x k
  {
    std::vector<std::vector<double>> a(m, std::vector<double>(m + k, 0.0));  // [B^T B | B^T]
    for (int r = 0; r < m; ++r) {
      for (int c = 0; c < m; ++c) {
        for (int j = 0; j < k; ++j) a[r][c] += b[j][r] * b[j][c];
      }
      for (int j = 0; j < k; ++j) a[r][m + j] = b[j][r];
    }
    for (int col = 0; col < m; ++col) {
      int pivot = col;
      for (int r = col + 1; r < m; ++r) {
        if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
      }
      std::swap(a[col], a[pivot]);
      for (int r = 0; r < m; ++r) {
        if (r == col) continue;
        const double factor = a[r][col] / a[col][col];
        for (int c = col; c < m + k; ++c) a[r][c] -= factor * a[col][c];
      }
    }
    for (int r = 0; r < m; ++r) {
      for (int j = 0; j < k; ++j) p[r][j] = a[r][m + j] / a[r][r];
    }
  }
  // Fitted values at the computed wavelengths, B P; the residual operator
  // is I - B P, interpolated linearly.
  std::vector<std::vector<double>> fit(k, std::vector<double>(k, 0.0));
  for (int j = 0; j < k; ++j) {
    for (int l = 0; l < k; ++l) {
      for (int f = 0; f < m; ++f) fit[j][l] += b[j][f] * p[f][l];
    }
  }
  result.log_weight.assign(n, std::vector<double>(k, 0.0));
  for (int i = 0; i < n; ++i) {
    const auto it = std::find(computed.begin(), computed.end(), i);
    if (it != computed.end()) {
      result.log_weight[i][it - computed.begin()] = 1.0;
      continue;
    }
    const std::array<double, 3> bi = basis(i);
    for (int l = 0; l < k; ++l) {
      double w = 0.0;
      for (int f = 0; f < m; ++f) w += bi[kept[f]] * p[f][l];
      for (int j = 0; j < k; ++j) w += linear[i][j] * ((j == l ? 1.0 : 0.0) - fit[j][l]);
      result.log_weight[i][l] = w;
    }
  }
  result.linear_weight = std::move(linear);
  return result;
}

namespace {

// The first batch's higher orders H_j (its table of all orders less its
// first orders' part, per channel j) and, per key, the reference spectrum
// N_j they are relative to (HigherOrderInterpolation). A texel's key is its
// index for the irradiance table and its sun for the scattering table: its
// mu_s column, (t % width) % mu_s_size, or below the table's split (where
// every ray has its own suns) mu_s_size and its index there.
struct HigherOrderSource {
  const glsl::Texture* all_orders = nullptr;
  const glsl::Texture* first_orders = nullptr;
  std::vector<glm::dvec3> reference;  // per key
  glm::dvec3 sun{0.0};                // E at its channels, the reference where a key has none
  std::size_t width = 0, height = 0, mu_s_size = 0;  // mu_s_size 0: the key is the texel's index
  const detail::OwnColumnSuns* own = nullptr;        // the table's suns below its split, if it has one
  int split = 0;

  std::size_t Key(std::size_t t) const {
    if (mu_s_size == 0) return t;
    const std::size_t x = t % width, column = x % mu_s_size;
    if (column >= std::size_t(split)) return column;
    return mu_s_size + own->Index(int(x), int(t / width % height), int(t / width / height));
  }
};

// The higher orders of one batch that does not compute them: per channel c,
// ln(H_c / N_c) = sum_j log_weight[c][j] ln(H_j / N_j) (or H_c / N_c =
// sum_j linear_weight[c][j] H_j / N_j where some H_j is not positive), with
// N the batch's reference per key and H_j, N_j the source's. Where either
// batch's reference is not positive at a key, both take the sun's spectrum,
// and where the sun is dark at a wavelength of either, 1 (H itself is
// interpolated, linearly where it is 0 at a computed wavelength).
struct InterpolatedBatch {
  glm::dmat3 log_weight{0.0}, linear_weight{0.0};  // column c: channel c's weights over j
  glm::dvec3 sun{0.0};
};

bool Positive(const glm::dvec3& v) { return v.x > 0.0 && v.y > 0.0 && v.z > 0.0; }

// Per texel and channel, the sum over batches of to_xyz times the batch's
// texel, in double until stored.
class XyzSum {
 public:
  explicit XyzSum(const glsl::Texture& shape)
      : width_(shape.width), height_(shape.height), depth_(shape.depth),
        sum_(std::size_t(shape.width) * shape.height * shape.depth, glm::dvec3(0.0)) {}

  void Add(const glm::dmat3& to_xyz, const glsl::Texture& texture) {
    ForEachTexel([&](std::size_t t) {
      const float* v = &texture.texels[4 * t];
      sum_[t] += to_xyz * glm::dvec3(v[0], v[1], v[2]);
    });
  }
  // to_xyz times the batch's `first_orders` texel plus its interpolated
  // higher orders.
  void AddInterpolated(const glm::dmat3& to_xyz, const glsl::Texture& first_orders, const HigherOrderSource& source,
                       const InterpolatedBatch& batch, const std::vector<glm::dvec3>& batch_reference) {
    // An exponent at most this far above the source's largest keeps an
    // extrapolation to the ends of the spectrum finite.
    constexpr double kLargestLogRatio = 20.0;
    const bool sunlit = Positive(source.sun) && Positive(batch.sun);
    const glm::dvec3 source_fallback = sunlit ? source.sun : glm::dvec3(1.0);
    const glm::dvec3 fallback = sunlit ? batch.sun : glm::dvec3(1.0);
    ForEachTexel([&](std::size_t t) {
      const std::size_t key = source.Key(t);
      const bool referenced = Positive(source.reference[key]) && Positive(batch_reference[key]);
      const glm::dvec3& source_reference = referenced ? source.reference[key] : source_fallback;
      const glm::dvec3& reference = referenced ? batch_reference[key] : fallback;
      const float* all = &source.all_orders->texels[4 * t];
      const float* first = &source.first_orders->texels[4 * t];
      const glm::dvec3 ratio =
          glm::dvec3(double(all[0]) - first[0], double(all[1]) - first[1], double(all[2]) - first[2]) /
          source_reference;
      glm::dvec3 higher;
      if (Positive(ratio)) {
        const glm::dvec3 log_ratio = glm::log(ratio);
        const double largest = std::max({log_ratio.x, log_ratio.y, log_ratio.z}) + kLargestLogRatio;
        higher = reference * glm::exp(glm::min(log_ratio * batch.log_weight, glm::dvec3(largest)));
      } else {
        higher = reference * glm::max(ratio * batch.linear_weight, glm::dvec3(0.0));
      }
      const float* v = &first_orders.texels[4 * t];
      sum_[t] += to_xyz * (glm::dvec3(v[0], v[1], v[2]) + higher);
    });
  }
  glsl::Texture Texture() const {
    glsl::Texture out(width_, height_, depth_);
    for (std::size_t i = 0; i < sum_.size(); ++i) {
      for (int c = 0; c < 3; ++c) out.texels[4 * i + c] = float(sum_[i][c]);
    }
    return out;
  }

 private:
  template <typename F>
  void ForEachTexel(F&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sum_.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t t = range.begin(); t != range.end(); ++t) f(t);
                      });
  }

  int width_, height_, depth_;
  std::vector<glm::dvec3> sum_;
};

// The reference spectra N of the higher orders' interpolation. For the
// irradiance table, the sky light of single scattering at the texel, I1: the
// next orders' light starts as it, and what they add is closer to it in
// colour than to the sun (docs/colour.md).
std::vector<glm::dvec3> IrradianceReference(const glsl::Texture& sky_light) {
  std::vector<glm::dvec3> reference;
  for (std::size_t t = 0; t < sky_light.texels.size() / 4; ++t) {
    reference.emplace_back(sky_light.texels[4 * t], sky_light.texels[4 * t + 1], sky_light.texels[4 * t + 2]);
  }
  return reference;
}

// For the scattering table, per mu_s column of `grid`: I1 on the ground
// under that sun (the runtime's lookup) at every altitude, as the higher
// orders anywhere in a column of air come mostly from its dense lower part
// (I1 aloft falls to 0 at the top, with no air above). That holds while the
// sun lights the air over the ground: once it is more than kLitAirDepth
// below the horizon, I1 comes from a thin, high sunlit shell whose colour
// the next orders do not share, and N turns to the sun's spectrum E,
// geometrically in between over kReferenceBlend (both measured,
// docs/colour.md). 0 where I1 is not positive (AddInterpolated then takes
// the sun's).
std::vector<glm::dvec3> ScatteringReference(const glsl::AtmosphereParameters& grid, const glsl::Texture& sky_light,
                                            const glm::dvec3& sun, const detail::OwnColumnSuns* own) {
  constexpr double kLitAirDepth = 4.0 * kPi / 180.0, kReferenceBlend = 4.0 * kPi / 180.0;
  auto reference_at = [&](double mu_s) {
    const double depth = std::acos(mu_s) - kPi / 2.0;
    const double w = std::clamp((kLitAirDepth + kReferenceBlend - depth) / kReferenceBlend, 0.0, 1.0);
    const glm::dvec3 light(glsl::GetIrradiance(grid, glsl::sampler2D{&sky_light}, grid.bottom_radius, mu_s));
    if (!Positive(light) || (w < 1.0 && !Positive(sun))) return glm::dvec3(0.0);
    return w < 1.0 ? glm::exp(w * glm::log(light) + (1.0 - w) * glm::log(sun)) : light;
  };
  const std::size_t columns = std::size_t(grid.scattering_mu_s_size);
  std::vector<glm::dvec3> reference(columns + (own ? own->size() : 0));
  for (std::size_t x = 0; x < columns; ++x) reference[x] = reference_at(GetScatteringTexel(grid, int(x), 0, 0).mu_s);
  if (own) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, own->size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i != range.end(); ++i) {
                          reference[columns + i] = reference_at(own->MuSAt(i));
                        }
                      });
  }
  return reference;
}

// Sunlight's colour through the transmittance table's rays, per texel and
// channel: -ln(sum_i a_i exp(-tau_i) / sum_i a_i) with a_i >= 0 the sun's
// XYZ weight at wavelength i, summed with the smallest depth factored out
// so that long, opaque rays do not underflow to 0.
class SunlightDepth {
 public:
  explicit SunlightDepth(const glsl::Texture& shape)
      : width_(shape.width), height_(shape.height), terms_(std::size_t(shape.width) * shape.height) {}

  // Column w of `sun_weights`: the XYZ weight of the depth in channel w.
  void Add(const glm::dmat3& sun_weights, const glsl::Texture& depth) {
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      for (int w = 0; w < 3; ++w) terms_[i].push_back({sun_weights[w], double(depth.texels[4 * i + w])});
    }
  }
  glsl::Texture Texture() const {
    glsl::Texture out(width_, height_);
    for (std::size_t i = 0; i < terms_.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        double smallest = std::numeric_limits<double>::infinity(), weight_sum = 0.0;
        for (const Term& t : terms_[i]) {
          if (t.weight[c] > 0.0) smallest = std::min(smallest, t.depth);
          weight_sum += t.weight[c];
        }
        double sum = 0.0;
        for (const Term& t : terms_[i]) sum += t.weight[c] * std::exp(smallest - t.depth);
        out.texels[4 * i + c] = weight_sum > 0.0 ? float(smallest - std::log(sum / weight_sum)) : 0.0f;
      }
    }
    return out;
  }

 private:
  struct Term {
    glm::dvec3 weight;  // per XYZ channel, of one wavelength
    double depth;
  };
  int width_, height_;
  std::vector<std::vector<Term>> terms_;
};

}  // namespace

LutSet BakeSpectral(const AtmosphereSource& source, const SpectralBatches& batches, const BakeSettings& settings,
                    BakeReport* report, const BakeProgress& progress) {
  if (settings.pack_single_mie_in_alpha) {
    throw InputError("--pack-mie: a spectral bake keeps single Mie in its own table (its alpha would hold one "
                     "wavelength, not a colour)");
  }
  if (settings.scattering_range) throw InputError("a spectral bake covers the whole atmosphere (no scene range)");
  // Every batch's atmosphere first, so that a file not defined at some
  // wavelength fails before anything is baked.
  std::vector<Atmosphere> atmospheres;
  for (const Spectrum& nm : batches.batch_wavelengths_nm) {
    atmospheres.push_back(ParseAtmosphere(source.text, source.name, nm));
  }
  // A bake of single scattering alone has no higher orders to interpolate.
  const bool interpolated = batches.higher_order_batches < batches.size() && settings.orders != 1;
  std::vector<InterpolatedBatch> interpolation(batches.size());
  LutSet out;
  out.atmosphere = ParseAtmosphere(source.text, source.name);
  out.colour = SpectralColour{batches.wavelengths_nm, batches.wavelengths_nm};
  if (interpolated) {
    // The interpolation's weights, from the atmosphere at each wavelength.
    const std::vector<int> computed = batches.HigherOrderWavelengths();
    const int n = static_cast<int>(batches.wavelengths_nm.size());
    std::vector<double> ground_scattering(n), absorption_depth(n);
    for (std::size_t b = 0; b < batches.size(); ++b) {
      const Atmosphere& atmosphere = atmospheres[b];
      // The vertical optical depth of the absorbers alone.
      Atmosphere absorbers = atmosphere;
      for (Constituent& c : absorbers.constituents) c.scattering_per_m = Spectrum(0.0);
      const Spectrum absorption = Medium(absorbers).OpticalDepth(atmosphere.bottom_radius_m, 1.0,
                                                                 atmosphere.top_radius_m - atmosphere.bottom_radius_m,
                                                                 settings.transmittance_samples);
      const Spectrum scattering_at_ground = atmosphere.ScatteringAt(0.0);
      for (int c = 0; c < kWavelengthCount; ++c) {
        const int i = batches.wavelength_index[b][c];
        if (i < 0) continue;
        ground_scattering[i] = scattering_at_ground[c];
        absorption_depth[i] = absorption[c];
      }
    }
    const HigherOrderInterpolation weights =
        MakeHigherOrderInterpolation(batches.wavelengths_nm, computed, ground_scattering, absorption_depth);
    // Channel j of the first batch is computed wavelength slot[j].
    std::array<int, kWavelengthCount> slot{};
    for (int j = 0; j < kWavelengthCount; ++j) {
      slot[j] = static_cast<int>(std::find(computed.begin(), computed.end(), batches.wavelength_index[0][j]) -
                                 computed.begin());
    }
    for (std::size_t b = 0; b < batches.size(); ++b) {
      InterpolatedBatch& batch = interpolation[b];
      batch.sun = glm::dvec3(atmospheres[b].solar_irradiance);
      for (int c = 0; c < kWavelengthCount; ++c) {
        const int i = batches.wavelength_index[b][c];
        if (i < 0) continue;  // a repeat, with no weight in XYZ
        for (int j = 0; j < kWavelengthCount; ++j) {
          batch.log_weight[c][j] = weights.log_weight[i][slot[j]];
          batch.linear_weight[c][j] = weights.linear_weight[i][slot[j]];
        }
      }
    }
    out.colour->higher_order_wavelengths_nm.clear();
    for (int i : computed) out.colour->higher_order_wavelengths_nm.push_back(batches.wavelengths_nm[i]);
  }

  std::optional<XyzSum> irradiance, scattering, single_mie;
  std::optional<SunlightDepth> transmittance;
  glm::dvec3 sun_xyz(0.0);
  using Profile = std::array<glsl::vec3, glsl::ALTITUDE_PROFILE_SIZE>;
  Profile extinction{}, mie{}, rayleigh{};
  BakeReport total;
  // The first batch's tables, which the others' interpolation reads: its
  // set, and its tables after the first and the second order (single
  // scattering, and the irradiance of its sky light).
  LutSet source_luts;
  glsl::Texture source_single_scattering, source_sky_light;
  HigherOrderSource scattering_source, irradiance_source;
  // The suns of the table's own columns, where it has a split: the same for
  // every batch (they depend on the geometry alone), solved by the first;
  // and the source's (the same ones).
  std::shared_ptr<const detail::OwnColumnSuns> own_suns, source_own_suns;
  for (std::size_t b = 0; b < batches.size(); ++b) {
    const Spectrum& nm = batches.batch_wavelengths_nm[b];
    const Atmosphere& atmosphere = atmospheres[b];
    const bool computes_higher_orders = !interpolated || b < batches.higher_order_batches;
    char name[64];
    std::snprintf(name, sizeof(name), "%.0f-%.0f nm: ", nm.x, nm.z);
    BakeSettings batch_settings = settings;
    if (!computes_higher_orders) {
      batch_settings.orders = 1;
      batch_settings.extrapolate_tail = false;
      batch_settings.single_scattering_sky_irradiance = true;
    }
    BakeReport batch_report;
    LutSet luts = detail::BakeSharingOwnSuns(
        atmosphere, batch_settings, &batch_report,
        [&](const BakeTiming& t) {
          if (progress) progress({name + t.phase, t.seconds});
        },
        {[&](int order, const LutSet& snapshot, double) {
           if (order == 1) source_single_scattering = snapshot.scattering;
           if (order == 2) source_sky_light = snapshot.irradiance;
         },
         interpolated && computes_higher_orders ? 2 : 0},
        &own_suns);
    for (const BakeTiming& t : batch_report.timings) total.timings.push_back({name + t.phase, t.seconds});
    total.total_seconds += batch_report.total_seconds;
    total.orders_used = std::max(total.orders_used, batch_report.orders_used);
    total.order_ratio = std::max(total.order_ratio, batch_report.order_ratio);
    total.extrapolated_tail = std::max(total.extrapolated_tail, batch_report.extrapolated_tail);
    total.remaining_error = std::max(total.remaining_error, batch_report.remaining_error);

    const glm::dmat3& m = batches.to_xyz[b];
    if (b == 0) {
      out.settings = luts.settings;
      out.parameters = luts.parameters;
      irradiance.emplace(luts.irradiance);
      scattering.emplace(luts.scattering);
      single_mie.emplace(luts.single_mie_scattering);
      transmittance.emplace(luts.transmittance);
    }
    out.orders_used = std::max(out.orders_used, luts.orders_used);
    if (computes_higher_orders) {
      irradiance->Add(m, luts.irradiance);
      scattering->Add(m, luts.scattering);
    } else {
      const glsl::AtmosphereParameters& grid = source_luts.parameters;
      irradiance->AddInterpolated(m, luts.irradiance, irradiance_source, interpolation[b],
                                  IrradianceReference(luts.irradiance));
      scattering->AddInterpolated(
          m, luts.scattering, scattering_source, interpolation[b],
          ScatteringReference(grid, luts.irradiance, interpolation[b].sun, source_own_suns.get()));
    }
    single_mie->Add(m, luts.single_mie_scattering);
    // The sun's XYZ weight of each of the batch's wavelengths: column w of m
    // times the irradiance there.
    const Spectrum& e = atmosphere.solar_irradiance;
    transmittance->Add(glm::dmat3(m[0] * e[0], m[1] * e[1], m[2] * e[2]), luts.transmittance);
    sun_xyz += m * e;
    const glsl::AtmosphereParameters& p = luts.parameters;
    for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
      extinction[i] += m * (e * p.extinction_profile[i]);
      mie[i] += m * (e * p.mie_scattering_profile[i]);
      rayleigh[i] += m * (e * p.rayleigh_scattering_profile[i]);
    }
    if (interpolated && b == 0) {
      // Kept for the batches after it; the others' tables go once added.
      source_luts = std::move(luts);
      const glsl::Texture& table = source_luts.scattering;
      scattering_source.all_orders = &table;
      scattering_source.first_orders = &source_single_scattering;
      const glsl::AtmosphereParameters& grid = source_luts.parameters;
      source_own_suns = own_suns;
      scattering_source.reference =
          ScatteringReference(grid, source_sky_light, interpolation[0].sun, source_own_suns.get());
      scattering_source.sun = interpolation[0].sun;
      scattering_source.width = std::size_t(table.width);
      scattering_source.height = std::size_t(table.height);
      scattering_source.mu_s_size = std::size_t(grid.scattering_mu_s_size);
      scattering_source.own = source_own_suns.get();
      scattering_source.split = grid.scattering_mu_s_split;
      irradiance_source = {&source_luts.irradiance, &source_sky_light, IrradianceReference(source_sky_light),
                           interpolation[0].sun};
    }
  }
  out.irradiance = irradiance->Texture();
  out.scattering = scattering->Texture();
  out.single_mie_scattering = single_mie->Texture();
  out.transmittance = transmittance->Texture();
  out.parameters.solar_irradiance = sun_xyz;
  out.parameters.transmittance_is_colour = 1;
  auto per_sun = [&](const glsl::vec3& v) {
    glsl::vec3 r(0.0);
    for (int c = 0; c < 3; ++c) r[c] = sun_xyz[c] > 0.0 ? v[c] / sun_xyz[c] : 0.0;
    return r;
  };
  for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
    out.parameters.extinction_profile[i] = per_sun(extinction[i]);
    out.parameters.mie_scattering_profile[i] = per_sun(mie[i]);
    out.parameters.rayleigh_scattering_profile[i] = per_sun(rayleigh[i]);
  }
  if (report) *report = total;
  return out;
}

}  // namespace skybake
