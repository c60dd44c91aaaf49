// The bake's public interface: the settings' checks, the atmosphere's GLSL
// parameters and grids, the texel geometry of the scattering table, and Bake().
#include "bake/bake.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "bake/baker.h"
#include "bake/medium.h"
#include "core/errors.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/twin.h"

namespace skybake {

ScatteringTexel GetScatteringTexel(const glsl::AtmosphereParameters& parameters, int x, int y, int z) {
  ScatteringTexel t;
  glsl::GetRMuMuSNuFromScatteringTextureUvwz(parameters, glsl::GetScatteringTextureUvwzFromTexel(parameters, x, y, z),
                                             t.r, t.mu, t.mu_s, t.grid_nu, t.ray_intersects_ground);
  t.nu = ClampedNu(t.grid_nu, t.mu, t.mu_s);
  return t;
}

ScatteringTexel GetScatteringSliceTexel(const glsl::AtmosphereParameters& parameters, int nu_index, int y, int z) {
  return GetScatteringTexel(parameters, (nu_index + 1) * parameters.scattering_mu_s_size - 1, y, z);
}

double ClampedNu(double nu, double mu, double mu_s) { return glsl::ClampNuToDirections(nu, mu, mu_s); }

double EstimatedBakeBytes(const BakeSettings& s) {
  constexpr double kFixedBytes = 160.0 * 1024.0 * 1024.0, kBytesPerTexel = 160.0;
  const double texels =
      double(s.scattering_r_size) * s.scattering_mu_size * s.scattering_mu_s_size * s.scattering_nu_size;
  return kFixedBytes + kBytesPerTexel * texels;
}

BakeSettings PreviewBakeSettings(BakeSettings settings) {
  BakeSettings& s = settings;
  s.transmittance_width = 128;
  s.transmittance_height = 32;
  s.irradiance_width = 32;
  s.irradiance_height = 8;
  s.scattering_r_size = 16;
  s.scattering_mu_size = 64;
  s.scattering_mu_s_size = 16;
  s.scattering_nu_size = 4;
  s.transmittance_samples = 16;
  s.ray_samples = 32;
  s.sphere_samples = 8;
  return s;
}

void BakeSettings::Validate() const {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw InputError(message);
  };
  auto size = [&](int value, int minimum, const char* name) {
    require(value >= minimum && value <= 4096,
            std::string(name) + " = " + std::to_string(value) + " must be in [" + std::to_string(minimum) + ", 4096]");
  };
  size(transmittance_width, 2, "transmittance width");
  size(transmittance_height, 2, "transmittance height");
  size(irradiance_width, 2, "irradiance width");
  size(irradiance_height, 2, "irradiance height");
  size(scattering_r_size, 2, "scattering r size");
  size(scattering_mu_size, 4, "scattering mu size");
  size(scattering_mu_s_size, 2, "scattering mu_s size");
  size(scattering_nu_size, 2, "scattering nu size");
  require(scattering_mu_size % 2 == 0,
          "scattering mu size = " + std::to_string(scattering_mu_size) + " must be even");
  require(orders >= 0 && orders <= 100, "orders = " + std::to_string(orders) + " must be in [1, 100] or 0 (auto)");
  require(max_orders >= 2 && max_orders <= 1000,
          "max orders = " + std::to_string(max_orders) + " must be in [2, 1000]");
  require(order_tolerance > 0.0 && order_tolerance < 1.0,
          "order tolerance = " + std::to_string(order_tolerance) + " must be in (0, 1)");
  require(transmittance_samples >= 8 && transmittance_samples <= 100000,
          "transmittance samples = " + std::to_string(transmittance_samples) + " must be in [8, 100000]");
  require(ray_samples >= 2 && ray_samples <= 100000,
          "ray samples = " + std::to_string(ray_samples) + " must be in [2, 100000]");
  require(higher_order_divisor >= 1 && higher_order_divisor <= 64,
          "higher-order divisor = " + std::to_string(higher_order_divisor) + " must be in [1, 64]");
  require(sphere_samples >= 2 && sphere_samples <= 1024,
          "sphere samples = " + std::to_string(sphere_samples) + " must be in [2, 1024]");
  require(threads >= 0 && threads <= kMaxThreads,
          "threads = " + std::to_string(threads) + " must be in [0, " + std::to_string(kMaxThreads) + "] (0: all cores)");
  if (const std::optional<ScatteringRange>& range = scattering_range) {
    require(range->altitude_min_m >= 0.0 && range->altitude_min_m < range->altitude_max_m,
            "scattering altitude range [" + std::to_string(range->altitude_min_m) + ", " +
                std::to_string(range->altitude_max_m) + "] m must be non-empty and above the ground");
    require(range->mu_s_min >= -1.0 && range->mu_s_min < range->mu_s_max && range->mu_s_max <= 1.0,
            "scattering mu_s range [" + std::to_string(range->mu_s_min) + ", " + std::to_string(range->mu_s_max) +
                "] must be non-empty and within [-1, 1]");
    size(range->atmosphere_r_size, 2, "scattering r size over the atmosphere");
    size(range->atmosphere_mu_size, 4, "scattering mu size over the atmosphere");
    size(range->atmosphere_mu_s_size, 2, "scattering mu_s size over the atmosphere");
    require(range->atmosphere_ray_samples >= 2 && range->atmosphere_ray_samples <= 100000,
            "ray samples over the atmosphere = " + std::to_string(range->atmosphere_ray_samples) +
                " must be in [2, 100000]");
    require(range->atmosphere_mu_size % 2 == 0, "scattering mu size over the atmosphere = " +
                                                    std::to_string(range->atmosphere_mu_size) + " must be even");
  }
}

namespace {
// The split of the scattering tables' sun axis (shadow_edge.glsl, "The sun
// axis after sunset"): the lowest column whose sun is at most 83 degrees
// from the zenith (on Earth's default table 82.6 degrees), where the sun
// is up for every point of every ray and the light changes slowly with it,
// so that the daylight sky reads as on columns at the same suns for every
// ray; where no column is that high, the highest, if its sun is at most 89
// degrees (every ray's shadow edge lies past 90 degrees and the disc's
// radius). 0, every column the same for every ray, where the tables'
// lowest sun is less than SHADOW_EDGE_LEAST_PAST_SPAN below the horizon
// (with no twilight to follow, the columns at and past each ray's edge
// would lie past the tables' suns), or where fewer than kLeastLitColumns
// would lie on the lit side (the ray's own axis then spreads too few over
// the low sun, whose light changes with the sunlight's air mass).
// docs/accuracy.md ("Twilight: a sun axis measured from each ray's shadow
// edge") measures both.
constexpr int kLeastLitColumns = 10;

int ScatteringMuSSplit(const glsl::AtmosphereParameters& p) {
  constexpr double kSplitSun = 83.0 * kPi / 180.0, kHighestSplitSun = 89.0 * kPi / 180.0;
  const int last = p.scattering_mu_s_size - 1;
  auto sun = [&](int column) { return std::acos(glsl::GetScatteringMuSFromUnitRange(p, double(column) / last)); };
  if (sun(0) < 0.5 * kPi + glsl::SHADOW_EDGE_LEAST_PAST_SPAN) return 0;
  int split = last;
  while (split > 0 && sun(split - 1) <= kSplitSun) --split;
  if (sun(split) > kHighestSplitSun || split < glsl::SHADOW_EDGE_PAST_COLUMNS + kLeastLitColumns) return 0;
  return split;
}
}  // namespace

void GroundScatteringOfMieAndOthers(const Atmosphere& atmosphere, Spectrum* mie, Spectrum* others) {
  Medium medium(atmosphere);
  *mie = Spectrum(0.0), *others = Spectrum(0.0);
  for (int g = 0; g < static_cast<int>(medium.groups().size()); ++g) {
    for (int c : medium.groups()[g].constituents) {
      const Constituent& constituent = atmosphere.constituents[c];
      *(g == medium.mie_group() ? mie : others) += constituent.scattering_per_m * constituent.density.At(0.0);
    }
  }
}

glsl::AtmosphereParameters MakeAtmosphereParameters(const Atmosphere& atmosphere, const BakeSettings& settings) {
  glsl::AtmosphereParameters p;
  p.solar_irradiance = atmosphere.solar_irradiance;
  p.sun_angular_radius = atmosphere.sun_angular_radius_rad;
  p.bottom_radius = atmosphere.bottom_radius_m;
  p.top_radius = atmosphere.top_radius_m;
  p.mu_s_min = atmosphere.mu_s_min;
  Medium medium(atmosphere);
  Spectrum mie_scattering, other_scattering;
  GroundScatteringOfMieAndOthers(atmosphere, &mie_scattering, &other_scattering);
  if (medium.mie_group() >= 0) {
    const PhaseFunction& phase = medium.groups()[medium.mie_group()].phase;
    p.mie_phase = phase.kind == PhaseKind::kHenyeyGreenstein ? glsl::PHASE_HENYEY_GREENSTEIN
                                                              : glsl::PHASE_CORNETTE_SHANKS;
    p.mie_g = phase.g;
  }
  if (settings.pack_single_mie_in_alpha) {
    bool ratio_defined = mie_scattering.x > 0.0 && other_scattering.x > 0.0 && other_scattering.y > 0.0 &&
                         other_scattering.z > 0.0;
    if (!ratio_defined) {
      throw InputError(atmosphere.name +
                       ": single Mie can only be packed into alpha when both the Mie and the other scattering "
                       "constituents scatter red light at the ground");
    }
    p.mie_to_rayleigh_scattering_ratio = mie_scattering / other_scattering;
    p.single_mie_in_scattering_alpha = 1;
  }
  p.transmittance_width = settings.transmittance_width;
  p.transmittance_height = settings.transmittance_height;
  p.scattering_r_size = settings.scattering_r_size;
  p.scattering_mu_size = settings.scattering_mu_size;
  p.scattering_mu_s_size = settings.scattering_mu_s_size;
  p.scattering_nu_size = settings.scattering_nu_size;
  p.irradiance_width = settings.irradiance_width;
  p.irradiance_height = settings.irradiance_height;
  p.scattering_r_min = atmosphere.bottom_radius_m;
  p.scattering_r_max = atmosphere.top_radius_m;
  p.scattering_mu_s_min = atmosphere.mu_s_min;
  p.scattering_mu_s_max = 1.0;
  if (const std::optional<ScatteringRange>& range = settings.scattering_range) {
    p.scattering_r_min = atmosphere.bottom_radius_m + range->altitude_min_m;
    p.scattering_r_max = atmosphere.bottom_radius_m + range->altitude_max_m;
    p.scattering_mu_s_min = range->mu_s_min;
    p.scattering_mu_s_max = range->mu_s_max;
  }
  p.scattering_mu_s_split = ScatteringMuSSplit(p);
  SetAltitudeProfiles(atmosphere, &p);
  return p;
}

glsl::AtmosphereParameters AtmosphereGrid(const Atmosphere& atmosphere, const BakeSettings& settings) {
  BakeSettings whole = settings;
  if (settings.scattering_range) {
    whole.scattering_range.reset();
    whole.scattering_r_size = settings.scattering_range->atmosphere_r_size;
    whole.scattering_mu_size = settings.scattering_range->atmosphere_mu_size;
    whole.scattering_mu_s_size = settings.scattering_range->atmosphere_mu_s_size;
  }
  glsl::AtmosphereParameters grid = MakeAtmosphereParameters(atmosphere, whole);
  grid.scattering_mu_s_split = 0;
  return grid;
}

void SetAltitudeProfiles(const Atmosphere& atmosphere, glsl::AtmosphereParameters* parameters) {
  const Medium medium(atmosphere);
  std::vector<double> densities(medium.constituent_count());
  const double height = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  for (int i = 0; i < glsl::ALTITUDE_PROFILE_SIZE; ++i) {
    // The sample altitudes of definitions.glsl.
    double x = double(i) / double(glsl::ALTITUDE_PROFILE_SIZE - 1);
    medium.Densities(height * x * x, densities.data());
    Spectrum mie(0.0), others(0.0);
    for (int g = 0; g < static_cast<int>(medium.groups().size()); ++g) {
      (g == medium.mie_group() ? mie : others) += medium.GroupScattering(g, densities.data());
    }
    parameters->extinction_profile[i] = medium.Extinction(densities.data());
    parameters->mie_scattering_profile[i] = mie;
    parameters->rayleigh_scattering_profile[i] = others;
  }
}

LutSet Bake(const Atmosphere& atmosphere, const BakeSettings& settings, BakeReport* report,
            const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot) {
  return detail::BakeSharingOwnSuns(atmosphere, settings, report, progress, order_snapshot, nullptr);
}

namespace detail {
LutSet BakeSharingOwnSuns(const Atmosphere& atmosphere, const BakeSettings& settings, BakeReport* report,
                          const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot,
                          std::shared_ptr<const OwnColumnSuns>* own_suns) {
  settings.Validate();
  std::unique_ptr<tbb::global_control> thread_limit;
  if (settings.threads > 0) {
    thread_limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                         static_cast<size_t>(settings.threads));
  }
  Baker baker(atmosphere, settings, own_suns ? *own_suns : nullptr);
  LutSet luts = baker.Run(report, progress, order_snapshot);
  if (own_suns) *own_suns = baker.own_suns();
  return luts;
}
}  // namespace detail

TwinTables MakeTwinTables(const LutSet& luts) {
  return TwinTables{luts.parameters, &luts.transmittance, &luts.scattering, &luts.single_mie_scattering,
                    &luts.irradiance};
}
}  // namespace skybake
