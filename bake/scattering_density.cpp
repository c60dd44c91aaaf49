// The scattering density of an order (light of the previous order scattered
// at a point) and the ground's indirect irradiance.
#include "bake/baker.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/grids.h"
#include "bake/ring_phase.h"
#include "bake/sun_lookups.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/quadrature.h"
#include "shaders_runtime/runtime.h"

namespace skybake::detail {
namespace {
// Width in cos(theta) (about 6 degrees) of the band above the horizon that
// AppendSkyRule resolves on its own.
constexpr double kHorizonBand = 0.1;

// A Gauss-Legendre rule in cos(theta) over the sky above a horizon of
// zenith cosine `horizon`: n nodes above kHorizonBand and band_nodes in the
// band just above the horizon. After sunset nearly all the light a point
// receives comes from within a few degrees above its horizon toward the sun
// (the lit air hundreds of kilometres away, seen over the shadow), and
// peaks steeply there; a rule spanning [horizon, 1] puts one or two nodes
// there, and misses or overweights that light differently at each
// wavelength. Both integrals give the band half of their polar nodes: with
// a quarter, the scattering density's, the second order seen deep in the
// shadow was up to 16 % from its value with four times the nodes, with
// half within 0.8 % (Twilight.SecondOrderDeepInTheShadowConvergedInTheSphereRule;
// docs/accuracy.md, "Twilight: the horizon band of the sphere's rule").
void AppendSkyRule(int n, int band_nodes, double horizon, std::vector<double>& cosines, std::vector<double>& weights) {
  AppendGaussLegendre(band_nodes, horizon, horizon + kHorizonBand, cosines, weights);
  AppendGaussLegendre(n, horizon + kHorizonBand, 1.0, cosines, weights);
}

// The scattering density's polar nodes in cos(theta) at a point whose
// horizon has zenith cosine `horizon`: half of `polar` below the horizon,
// half in the sky above it (AppendSkyRule, which adds the band next to
// it). The incident radiance jumps at the horizon (long grazing sky paths
// above, the ground below), which a rule spanning it converges on slowly.
void AppendDensityRule(int polar, double horizon, std::vector<double>& cosines, std::vector<double>& weights) {
  AppendGaussLegendre(polar / 2, -1.0, horizon, cosines, weights);
  AppendSkyRule(polar - polar / 2, std::max(1, polar / 2), horizon, cosines, weights);
}

// The cosines and sines of a sphere rule's azimuths (m + 1/2) 2 pi / count,
// m = 0 ... count - 1, the same on every ring: computed once per rule.
struct RingAzimuths {
  std::vector<double> cos, sin;
  explicit RingAzimuths(int count) {
    for (int m = 0; m < count; ++m) {
      const double phi = (m + 0.5) * (2.0 * kPi / count);
      cos.push_back(std::cos(phi));
      sin.push_back(std::sin(phi));
    }
  }
};

}  // namespace

vec3 Baker::DirectIrradiance(double r, double mu_s) const {
  // Cosine factor averaged over the sun's disc when it straddles the horizon.
  double alpha = params_.sun_angular_radius;
  double cosine = mu_s < -alpha ? 0.0 : (mu_s > alpha ? mu_s : (mu_s + alpha) * (mu_s + alpha) / (4.0 * alpha));
  return params_.solar_irradiance *
         glsl::GetTransmittanceToTopAtmosphereBoundary(params_, glsl::sampler2D{&transmittance_}, r, mu_s) * cosine;
}

vec3 Baker::GroundIrradiance(int order, double mu_s) const {
  if (order == 1) return DirectIrradiance(params_.bottom_radius, mu_s);
  return glsl::GetIrradiance(params_, glsl::sampler2D{&delta_irradiance_}, params_.bottom_radius, mu_s);
}

Baker::IncidentAlongNu::IncidentAlongNu(const Baker& baker, int order, double r, double mu, double mu_s,
                                        bool intersects_ground)
    : params_(baker.params_), single_(order == 1) {
  const AtmosphereParameters& grid = single_ ? baker.atmosphere_grid_ : baker.orders_grid_;
  nu_size_ = grid.scattering_nu_size;
  // glsl::GetScattering's lookups of the nu slices 0 ... nu_size (the last
  // clamped to the edge, as the texture unit does), which nu only blends.
  // Along mu_s the texture unit's linear blend, which is the lookup's own
  // in daylight; a low sun is read only at the grid's mu_s columns (the
  // density's rings sit on them, and the irradiance of a low sun is
  // integrated there), where no blend along mu_s enters.
  const vec4 uvwz = glsl::GetScatteringTextureUvwzFromRMuMuSNu(grid, r, mu, mu_s, 0.0, intersects_ground);
  double x_below, x_above, mu_s_t;
  bool low_sun;
  glsl::GetScatteringMuSColumns(grid, uvwz.y, glsl::GetScatteringTextureUMuS(grid, glsl::LOW_SUN_MU_S), x_below,
                                x_above, mu_s_t, low_sun);
  if (low_sun && std::abs(mu_s_t) > 1e-9 && std::abs(1.0 - mu_s_t) > 1e-9) {
    throw InternalError("IncidentAlongNu: a low sun between two mu_s columns of the scattering grid");
  }
  auto slices = [&](const Texture& table, std::vector<vec3>& out) {
    const glsl::sampler3D sampler{&table};
    out.reserve(nu_size_ + 1);
    for (int slice = 0; slice <= nu_size_; ++slice) {
      out.push_back(vec3(glsl::texture(sampler, glsl::vec3((slice + uvwz.y) / nu_size_, uvwz.z, uvwz.w))));
    }
  };
  if (single_) {
    slices(baker.GridSingle().rayleigh, first_);
    slices(baker.GridSingle().mie, second_);
  } else {
    slices(baker.delta_multiple_, first_);
  }
}

vec3 Baker::IncidentAlongNu::At(double nu) const {
  // glsl::GetScattering's blend of the two slices around nu.
  const double coordinate = glsl::ScatteringUnitNu(nu) * (nu_size_ - 1);
  const double slice = std::floor(coordinate), lerp = coordinate - slice;
  const int i = std::clamp(static_cast<int>(slice), 0, nu_size_ - 1);
  const vec3 first = first_[i] * (1.0 - lerp) + first_[i + 1] * lerp;
  if (!single_) return first;
  const vec3 mie = second_[i] * (1.0 - lerp) + second_[i + 1] * lerp;
  return first * glsl::RayleighPhaseFunction(nu) + mie * glsl::MiePhaseFunction(params_, nu);
}

Baker::RingSingleScattering Baker::SingleScatteringOnRings(const std::vector<double>& radii,
                                                            const std::vector<std::vector<double>>& ring_cosines,
                                                            const std::vector<double>& sun_mu_s, int azimuths) const {
  RingSingleScattering result;
  result.columns = static_cast<int>(sun_mu_s.size());
  result.azimuths = azimuths;
  result.half_azimuths = azimuths / 2;
  result.rings = ring_cosines.empty() ? 0 : static_cast<int>(ring_cosines.front().size());
  if (result.columns == 0 || result.rings == 0) return result;
  // Half the single-scattering table's intervals: the sphere's rule
  // averages these (the full count changes no case group by more than
  // 0.05 %, at twice the cost; a quarter of it the report's twilight group
  // by 0.2 %).
  const int ray_samples =
      std::max(8, (TableRestricted() ? settings_.scattering_range->atmosphere_ray_samples : settings_.ray_samples) / 2);
  const RingAzimuths azimuth(azimuths);
  const ChannelPlanes transmittance(transmittance_);
  result.of_ring.resize(radii.size() * result.rings);
  tbb::parallel_for(0, static_cast<int>(result.of_ring.size()), [&](int index) {
    const int i = index / result.rings, l = index % result.rings;
    const double r = radii[i], cos_theta = ring_cosines[i][l];
    const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
    // The ring's sun directions: per column, the azimuths from the sun's to the opposite.
    std::vector<double> mu_s, nu;
    for (double column_mu_s : sun_mu_s) {
      const double sun_sin = std::sqrt(std::max(0.0, 1.0 - column_mu_s * column_mu_s));
      for (int m = 0; m < result.half_azimuths; ++m) {
        mu_s.push_back(column_mu_s);
        nu.push_back(glsl::ClampCosine(azimuth.cos[m] * sin_theta * sun_sin + cos_theta * column_mu_s));
      }
    }
    const RaySamples ray = SampleRay(r, cos_theta, glsl::RayIntersectsGround(params_, r, cos_theta), ray_samples);
    result.of_ring[index] = SingleScatteringOfRay(ray, mu_s, nu, transmittance);
  });
  return result;
}

std::optional<vec3> Baker::RingIncident(const RingSingleScattering& rings, int radius, int ring, int column, int m,
                                        double nu) const {
  if (column >= rings.columns || rings.of_ring.empty()) return std::nullopt;
  // The light is symmetric about the sun's plane: azimuth m has the single
  // scattering of its mirror image 2 pi - phi.
  const int j = column * rings.half_azimuths + (m < rings.half_azimuths ? m : rings.azimuths - 1 - m);
  const auto& sums = rings.of_ring[std::size_t(radius) * rings.rings + ring].sums;
  const vec3 rayleigh(sums[0][0][j], sums[0][1][j], sums[0][2][j]), mie(sums[1][0][j], sums[1][1][j], sums[1][2][j]);
  return (rayleigh * glsl::RayleighPhaseFunction(nu) + mie * glsl::MiePhaseFunction(params_, nu)) *
         params_.solar_irradiance;
}

void Baker::ComputeScatteringDensity(int order) {
  const AtmosphereParameters& grid = atmosphere_grid_;
  const int mu_s_size = grid.scattering_mu_s_size, r_size = grid.scattering_r_size;
  const int nu_size = grid.scattering_nu_size, mu_size = grid.scattering_mu_size;
  const int polar = settings_.sphere_samples, azimuths = 2 * settings_.sphere_samples;
  const RingAzimuths azimuth(azimuths);
  const int groups = static_cast<int>(medium_.groups().size());
  const vec3 albedo_over_pi = medium_.atmosphere().ground_albedo / kPi;
  const glsl::sampler2D transmittance{&transmittance_};

  const SunColumns columns(grid);
  // Per r row, its radius and the polar nodes of its sphere rule.
  std::vector<double> radii;
  std::vector<std::vector<double>> ring_cosines(r_size), ring_weights(r_size);
  for (int z = 0; z < r_size; ++z) {
    radii.push_back(GetScatteringSliceTexel(grid, 0, 0, z).r);
    AppendDensityRule(polar, glsl::HorizonZenithCosine(params_.bottom_radius, radii.back()), ring_cosines[z],
                      ring_weights[z]);
  }
  RingSingleScattering ring_single;
  if (order == 2) {
    const std::vector<double> low_sun(columns.mu_s.begin(), columns.mu_s.begin() + LowSunColumnCount(columns));
    ring_single = SingleScatteringOnRings(radii, ring_cosines, low_sun, azimuths);
  }
  // Per r row, the weights of the rings' series terms in the mean of each
  // mu row's view (RingPhaseMeans), the same for every order: kept for the
  // later orders up to kKeptPhaseWeightBytes (the default rule's are 19
  // MiB; they grow as the square of the sphere samples, to 302 MiB at 64),
  // else computed again per order and view, where they are used.
  constexpr std::size_t kKeptPhaseWeightBytes = std::size_t(128) << 20;
  const int terms = azimuths / 2;
  const int rings = static_cast<int>(ring_cosines.front().size());
  const int stride = RingPhaseMeans::StrideFor(terms);
  const bool keep_weights =
      RingPhaseMeans::WeightBytes(std::size_t(r_size) * mu_size, rings, terms) <= kKeptPhaseWeightBytes;
  std::vector<PhaseAzimuthSeries> series;
  for (int g = 0; g < groups; ++g) series.emplace_back(medium_.groups()[g].phase, terms);
  std::vector<double> view_mu(std::size_t(r_size) * mu_size);
  for (int z = 0; z < r_size; ++z) {
    for (int y = 0; y < mu_size; ++y) view_mu[std::size_t(z) * mu_size + y] = GetScatteringSliceTexel(grid, 0, y, z).mu;
  }
  // The weights of row z for its views [first, end).
  auto row_weights = [&](int z, int first, int end) {
    // Each group's share of the scattering at the row's radius, per channel.
    std::vector<double> densities(medium_.constituent_count());
    medium_.Densities(radii[z] - params_.bottom_radius, densities.data());
    std::vector<Spectrum> shares(groups);
    Spectrum total(0.0);
    for (int g = 0; g < groups; ++g) total += shares[g] = medium_.GroupScattering(g, densities.data());
    for (Spectrum& share : shares) {
      for (int c = 0; c < 3; ++c) share[c] = total[c] > 0.0 ? share[c] / total[c] : 0.0;
    }
    const auto row = view_mu.begin() + std::ptrdiff_t(z) * mu_size;
    return std::make_unique<RingPhaseMeans>(series, shares, std::vector<double>(row + first, row + end),
                                            ring_cosines[z], ring_weights[z], terms);
  };
  if (keep_weights && density_phase_.empty()) {
    density_phase_.resize(r_size);
    tbb::parallel_for(0, r_size, [&](int z) { density_phase_[z] = row_weights(z, 0, mu_size); });
  }

  // Row by row: the incoming radiance's series on the rings per sun, then
  // the texels' means, which read each view's weights once for all suns.
  const AzimuthCosineSeries cosine_series(terms);
  const std::size_t slice_terms = std::size_t(3) * rings * stride;
  std::vector<float> ring_series(mu_s_size * slice_terms, 0.0f);
  for (int z = 0; z < r_size; ++z) {
    const double r = radii[z];
    const std::vector<double>& cosines = ring_cosines[z];
    tbb::parallel_for(0, mu_s_size, [&](int mu_s_index) {
      const double mu_s = columns.mu_s[mu_s_index];
      // Local frame: zenith along z, sun in the x-z plane.
      const vec3 zenith(0.0, 0.0, 1.0);
      const vec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
      // Incoming radiance (of the previous order) on every ring, at the
      // azimuths on the sun's side of its plane of symmetry (the light is
      // symmetric about it), per channel; then its cosine series per ring.
      std::vector<double> radiance(std::size_t(3) * rings * terms);
      for (int l = 0; l < rings; ++l) {
        double cos_theta = cosines[l], sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
        bool intersects = glsl::RayIntersectsGround(params_, r, cos_theta);
        double ground_distance = 0.0;
        vec3 ground_transmittance(0.0);
        if (intersects) {
          ground_distance = glsl::DistanceToBottomAtmosphereBoundary(params_, r, cos_theta);
          ground_transmittance = glsl::GetTransmittance(params_, transmittance, r, cos_theta, ground_distance, true);
        }
        const IncidentAlongNu incident_ring(*this, order - 1, r, cos_theta, mu_s, intersects);
        for (int m = 0; m < terms; ++m) {
          vec3 omega(azimuth.cos[m] * sin_theta, azimuth.sin[m] * sin_theta, cos_theta);
          double nu = glsl::ClampCosine(glm::dot(omega, sun));
          const std::optional<vec3> exact = RingIncident(ring_single, z, l, mu_s_index, m, nu);
          vec3 incident = exact ? *exact : incident_ring.At(nu);
          if (intersects) {
            vec3 ground_normal = glm::normalize(zenith * r + omega * ground_distance);
            double ground_mu_s = glsl::ClampCosine(glm::dot(ground_normal, sun));
            incident += ground_transmittance * albedo_over_pi * GroundIrradiance(order - 1, ground_mu_s);
          }
          for (int c = 0; c < 3; ++c) radiance[(std::size_t(c) * rings + l) * terms + m] = incident[c];
        }
      }
      for (int ring = 0; ring < 3 * rings; ++ring) {
        cosine_series.Coefficients(&radiance[std::size_t(ring) * terms],
                                   &ring_series[mu_s_index * slice_terms + std::size_t(ring) * stride]);
      }
    });

    // Stored per unit scattering coefficient, i.e. as the phase-weighted
    // mean incoming radiance, which varies slowly with altitude; the
    // multiple-scattering integral multiplies the coefficient back at each
    // sample. Interpolating J itself between r texels overestimates a thin
    // exponential haze (linear interpolation of a convex profile), so that
    // an order could carry more light than the previous one and the orders
    // of a dense fog diverged.
    tbb::parallel_for(0, mu_size, [&](int y) {
      std::unique_ptr<RingPhaseMeans> computed;
      if (!keep_weights) computed = row_weights(z, y, y + 1);
      const RingPhaseMeans& means = keep_weights ? *density_phase_[z] : *computed;
      const int view = keep_weights ? y : 0;
      std::vector<float> view_terms(std::size_t(3) * stride);
      std::vector<double> cos_phi(nu_size), multiples(std::size_t(terms) * nu_size);
      std::vector<vec3> per_unit_scattering(nu_size);
      const double mu = view_mu[std::size_t(z) * mu_size + y];
      const double sin_mu = std::sqrt(std::max(0.0, 1.0 - mu * mu));
      for (int mu_s_index = 0; mu_s_index < mu_s_size; ++mu_s_index) {
        const double mu_s = columns.mu_s[mu_s_index];
        const double sin_mu_s = std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s));
        // The views' azimuths from the sun, for zenith cosine mu and sun cosine nu.
        for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
          const double nu = ClampedNu(columns.grid_nu[nu_index * mu_s_size + mu_s_index], mu, mu_s);
          cos_phi[nu_index] =
              sin_mu * sin_mu_s > 0.0 ? std::clamp((nu - mu * mu_s) / (sin_mu * sin_mu_s), -1.0, 1.0) : 1.0;
        }
        CosineMultiples(cos_phi.data(), nu_size, terms, multiples.data());
        means.Terms(view, &ring_series[mu_s_index * slice_terms], view_terms.data());
        for (int c = 0; c < 3; ++c) {
          for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
            double sum = 0.0;
            for (int k = 0; k < terms; ++k) {
              sum += view_terms[std::size_t(c) * stride + k] * multiples[std::size_t(k) * nu_size + nu_index];
            }
            per_unit_scattering[nu_index][c] = sum;
          }
        }
        for (int nu_index = 0; nu_index < nu_size; ++nu_index) {
          scattering_density_.Store(nu_index * mu_s_size + mu_s_index, y, z, vec4(per_unit_scattering[nu_index], 0.0));
        }
      }
    });
  }
}

void Baker::ComputeIndirectIrradiance(int order) {
  const int width = irradiance_.width, height = irradiance_.height;
  const int polar = settings_.sphere_samples, azimuths = 4 * settings_.sphere_samples;
  const double d_phi = 2.0 * kPi / azimuths;
  const RingAzimuths azimuth(azimuths);
  // Polar nodes in cos(theta) over the upper hemisphere: the irradiance is
  // the integral of L cos(theta) d cos(theta) d phi.
  std::vector<double> cosines, cosine_weights;
  AppendSkyRule(polar, std::max(1, polar / 2), 0.0, cosines, cosine_weights);
  // `ring_single`: the first order's light on the rings at the columns
  // where the irradiance is integrated (below), integrated along the rings
  // (see RingSingleScattering); the irradiance at row y, column `column`
  // reads it.
  RingSingleScattering ring_single;
  auto sky_irradiance = [&](double r, double mu_s, int y = -1, int column = -1) {
    const vec3 sun(std::sqrt(std::max(0.0, 1.0 - mu_s * mu_s)), 0.0, mu_s);
    vec3 result(0.0);
    for (std::size_t l = 0; l < cosines.size(); ++l) {
      const double cos_theta = cosines[l], sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
      const IncidentAlongNu incident_ring(*this, order, r, cos_theta, mu_s, false);
      for (int m = 0; m < azimuths; ++m) {
        vec3 omega(azimuth.cos[m] * sin_theta, azimuth.sin[m] * sin_theta, cos_theta);
        double nu = glsl::ClampCosine(glm::dot(omega, sun));
        const std::optional<vec3> exact =
            column >= 0 ? RingIncident(ring_single, y, static_cast<int>(l), column, m, nu) : std::nullopt;
        result += (exact ? *exact : incident_ring.At(nu)) * (cos_theta * cosine_weights[l] * d_phi);
      }
    }
    return result;
  };
  // Where the sun is low, an irradiance integrated from the scattering
  // table at a sun between two of its mu_s columns would follow the table's
  // blend between them, which is the lookup's and not the irradiance's own.
  // After sunset ln E is concave in the sun's angle (its fall steepens as
  // the sun sinks), and the geometric blend read up to 5-9 % low at
  // mid-column (docs/accuracy.md). There the irradiance is integrated at
  // the columns themselves, where the table needs no blend along mu_s, and
  // read between them by the runtime's monotone cubic in ln over four
  // columns (glsl::LogMonotoneCubicMix).
  const AtmosphereParameters& grid = order == 1 ? atmosphere_grid_ : orders_grid_;  // as IncidentAlongNu reads
  const int mu_s_size = grid.scattering_mu_s_size;
  const SunColumns columns(grid);
  const int low_sun_columns = LowSunColumnCount(columns);
  const int integrated_columns = std::min(mu_s_size, low_sun_columns + 2);  // and two above, for the cubic
  auto row_radius = [&](int y) {
    double r, mu_s;
    glsl::GetRMuSFromIrradianceTextureUv(params_, glsl::vec2(0.5 / width, (y + 0.5) / height), r, mu_s);
    return r;
  };
  if (order == 1) {
    std::vector<double> radii, integrated(columns.mu_s.begin(), columns.mu_s.begin() + integrated_columns);
    for (int y = 0; y < height; ++y) radii.push_back(row_radius(y));
    ring_single = SingleScatteringOnRings(radii, std::vector<std::vector<double>>(height, cosines), integrated, azimuths);
  }
  tbb::parallel_for(0, height, [&](int y) {
    double r = row_radius(y), mu_s;
    std::vector<vec3> at_columns(integrated_columns);
    for (int k = 0; k < integrated_columns; ++k) at_columns[k] = sky_irradiance(r, columns.mu_s[k], y, k);
    for (int x = 0; x < width; ++x) {
      glsl::GetRMuSFromIrradianceTextureUv(params_, glsl::vec2((x + 0.5) / width, (y + 0.5) / height), r, mu_s);
      const double position = glsl::GetScatteringTextureUMuS(grid, mu_s) * mu_s_size - 0.5;
      const int column = std::clamp(static_cast<int>(std::floor(position)), 0, mu_s_size - 2);
      vec3 result;
      if (columns.mu_s[column] < glsl::LOW_SUN_MU_S) {
        auto at = [&](int k) { return vec4(at_columns[std::clamp(k, 0, integrated_columns - 1)], 0.0); };
        result = vec3(glsl::LogMonotoneCubicMix(at(column - 1), at(column), at(column + 1), at(column + 2), column > 0,
                                                column + 2 < integrated_columns,
                                                std::clamp(position - column, 0.0, 1.0)));
      } else {
        result = sky_irradiance(r, mu_s);
      }
      delta_irradiance_.Store(x, y, 0, vec4(result, 0.0));
      vec4 total = irradiance_.Fetch(x, y) + vec4(result, 0.0);
      irradiance_.Store(x, y, 0, total);
    }
  });
}
}  // namespace skybake::detail
