// The CPU bake. The structure follows Bruneton's precomputation (transmittance,
// single scattering, then per order: scattering density, indirect irradiance,
// multiple scattering), with four CPU-specific choices:
//
// * Rays are shared. Every texel of the 4D table with the same (r, mu) looks
//   along the same ray, so the samples along it, the densities and the
//   optical depth from the camera are computed once per ray and reused by all
//   (mu_s, nu) texels; only the sun's transmittance and the looked-up source
//   differ.
// * Incoming radiance is shared. The radiance arriving at a point depends on
//   its altitude and the sun's zenith angle, not on the view direction, so
//   the scattering density gathers the incoming radiance once per (r, mu_s)
//   slice and reuses it for all (mu, nu) view texels of the slice.
// * Gathering is a weighted sum. Along a ray the scattering density J is
//   taken as linear between samples and the rest of the integrand as
//   exponential, so the weights are computed once per ray and each of its
//   texels sums weight times J. Being linear in J, it can also gather the
//   summed densities of all orders once, when each order's own radiance is
//   gathered on a coarser grid (BakeSettings::higher_order_divisor).
// * The innermost loops run over a ray's sun directions, in float, and
//   vectorise (bake/float_math.h); the geometry that decides the planet's
//   shadow stays in double.
//   docs/benchmark.md measures each choice's time and error.
//
// Integrals along rays use the exponential trapezoid rule (exact when the
// integrand varies exponentially between samples, as densities and
// transmittances do), so a thin haze layer seen on a steep ray needs no more
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/detail.h"
#include "bake/grids.h"
#include "bake/medium.h"
#include "bake/ray_integrals.h"
#include "bake/ring_phase.h"
#include "bake/sun_lookups.h"

namespace skybake::detail {
class Baker {
 public:
  // own_suns: the suns of the table's own columns if already solved for a
  // table of the same geometry (a spectral bake's other batches), else null.
  Baker(const Atmosphere& atmosphere, const BakeSettings& settings,
        std::shared_ptr<const OwnColumnSuns> own_suns = nullptr)
      : medium_(atmosphere),
        settings_(settings),
        params_(MakeAtmosphereParameters(atmosphere, settings)),
        atmosphere_grid_(AtmosphereGrid(atmosphere, settings)),
        orders_grid_(HigherOrderGrid(atmosphere_grid_, settings.higher_order_divisor)),
        own_suns_(std::move(own_suns)) {}

  // The suns of the table's own columns, where it has a split (after Run).
  std::shared_ptr<const OwnColumnSuns> own_suns() const { return own_suns_; }

  LutSet Run(BakeReport* report, const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot);

 private:
  template <typename F>
  void Phase(const std::string& name, F&& work);

  // Single scattering on a grid, Rayleigh (the other groups) and Mie apart,
  // both phase free.
  struct SingleScattering {
    Texture rayleigh, mie;
  };

  void ComputeTransmittance();
  // Single scattering on `grid`, with `ray_samples` intervals per ray;
  // `own`: the suns of the rays' own columns where the grid has a split.
  // Along the same rays, that of `other`'s columns into `other_out` (a
  // texture of its grid's size), where given.
  SingleScattering ComputeSingleScattering(const AtmosphereParameters& grid, int ray_samples, const OwnColumnSuns* own,
                                           const OtherColumns& other = {}, SingleScattering* other_out = nullptr) const;
  // Single scattering of the texels of one ray of `grid` (mu index y, r
  // index z), n intervals, into `out`, and of `other`'s into `other_out`.
  // `columns`, `own`: the grid's sun directions (RaySunDirections);
  // `transmittance`: the transmittance table's channels.
  void SingleScatteringAlongRay(const AtmosphereParameters& grid, int n, int y, int z, const SunColumns& columns,
                                const OwnColumnSuns* own, const OtherColumns& other, const ChannelPlanes& transmittance,
                                SingleScattering& out, SingleScattering* other_out) const;
  // Per sun direction of a ray, its single scattering before the solar
  // irradiance: sums[0] the scattering table's (every group but the Mie
  // group, over the Rayleigh phase), sums[1] the single Mie table's (phase
  // free); per channel.
  struct RaySingleScattering {
    std::vector<float> sums[2][3];
  };
  // Single scattering along `ray` for the sun directions (mu_s[j], nu[j]).
  RaySingleScattering SingleScatteringOfRay(const RaySamples& ray, const std::vector<double>& mu_s,
                                            const std::vector<double>& nu, const ChannelPlanes& transmittance) const;
  // Single scattering over interval k of a ray for one sun direction, in
  // double, for the intervals SingleScatteringOfRay does not vectorise:
  // optically thick, partly shadowed or crossed by the shadow edge.
  // phase_ratio: per group, its phase over the Rayleigh phase at nu.
  void SingleScatteringInterval(const RaySamples& ray, int k, double mu_s, double nu, const double* phase_ratio,
                                Spectrum& rayleigh_sum, Spectrum& mie_sum) const;
  // The scattering density of the second order and the first order's sky
  // irradiance read the light arriving at a point from single scattering.
  // For a low sun that light peaks sharply toward the sun's azimuth near the
  // horizon, where the single-scattering table's nu slices are about 40
  // degrees of azimuth apart and its linear blend between them reads the
  // peak tens of percent high; so at the low-sun columns (mu_s <
  // LOW_SUN_MU_S, and for the irradiance the two above, which its cubic
  // reads) it is integrated along each ring's own ray instead, at every
  // azimuth (there the orders' grid has no single scattering of its own
  // where the table's columns are each ray's: Run). Per (radius, ring), the
  // sums of SingleScatteringOfRay for the directions j * half_azimuths + m:
  // sun column j, azimuth index m from the sun's (the light is symmetric
  // about the sun's plane, so the mirror azimuths share them).
  struct RingSingleScattering {
    int columns = 0, rings = 0, azimuths = 0, half_azimuths = 0;
    std::vector<RaySingleScattering> of_ring;
  };
  // For rings of zenith cosines ring_cosines[i] (as many for every radius)
  // at radii[i], the sun at each of sun_mu_s, `azimuths` around each ring.
  RingSingleScattering SingleScatteringOnRings(const std::vector<double>& radii,
                                               const std::vector<std::vector<double>>& ring_cosines,
                                               const std::vector<double>& sun_mu_s, int azimuths) const;
  // The single scattering arriving along `ring` at radius index `radius`
  // from azimuth index m (whose nu is `nu`) with the sun at `column`, with
  // its phase and the solar irradiance; none where it was not integrated.
  std::optional<vec3> RingIncident(const RingSingleScattering& rings, int radius, int ring, int column, int m,
                                   double nu) const;
  void ComputeScatteringDensity(int order);
  void ComputeIndirectIrradiance(int order);
  // How J falls along mu_s, read by GatherAlongRays. With
  // `between_columns` (the second order), per texel of a scattering grid
  // whose sun is below the horizon (mu_s < 0), for the pair of it and its
  // neighbour toward the higher sun: the ln of the ratio of their J summed
  // over the channels (log_ratio > 0, as after sunset J rises with the sun)
  // and 1 / (ratio - 1); 0 and 0 where J does not rise; per (r, mu) row, nu
  // slice, then column. Always, per row, nu slice and channel, the fall of
  // J below the grid's lowest sun: LowestSunLogFall's slope and curvature
  // of ln J in mu_s from the two lowest columns.
  struct MuSFall {
    LargeBuffer<float> log_ratio, inverse_ratio_minus_one;
    int falling_columns = 0;  // the columns with mu_s < 0, lowest first (not the last)
    float steady_mu_s = 0.0f;  // mu_s of the first column that does not fall
    std::vector<float> lowest_log_slope, lowest_log_curvature;
  };
  MuSFall MuSFallOf(const Texture& density, bool between_columns) const;
  // The rays of a table on the grid `grid` (`own`: the suns of its rays'
  // own columns where it has a split), prepared for gathering densities on
  // the grid `density_grid`: what each gather needs of them whatever the
  // density (gather.cpp), built once for all the orders.
  struct GatherPlan;
  std::shared_ptr<GatherPlan> PlanGather(const AtmosphereParameters& grid, const OwnColumnSuns* own,
                                         const AtmosphereParameters& density_grid) const;
  // A plan along the rays of `plan` for a grid with the same r and mu rows
  // and other mu_s columns (`own`: its rays' own columns' suns).
  std::shared_ptr<GatherPlan> PlanGatherForColumns(const GatherPlan& plan, const AtmosphereParameters& grid,
                                                   const OwnColumnSuns* own) const;
  // The light of the orders whose scattering density (per unit scattering
  // coefficient, on the plan's density grid) is `density`, arriving at
  // every texel of a table on the plan's grid: the density integrated along
  // each texel's ray. J is read linearly in r and mu; along mu_s linearly,
  // or where `fall` has falls between columns, with weights that follow
  // them (exactly where J is exponential between two columns). Given
  // `fall`, J below the grid's lowest sun continues the fall of the two
  // lowest columns per channel instead of holding the lowest column. Into
  // `result`, in the memory it has.
  void GatherAlongRays(GatherPlan& plan, const Texture& density, const MuSFall* fall, Texture* result) const;
  // Whether the table covers less than the whole atmosphere (a scene's bake):
  // its grid is then not the one the orders are computed on.
  bool TableRestricted() const { return settings_.scattering_range.has_value(); }
  // Whether the table's grid is the one the orders are computed on: not
  // where it is restricted, nor where its mu_s columns below the split are
  // each ray's own (shadow_edge.glsl, "The sun axis after sunset").
  bool TableOnAtmosphereGrid() const { return !TableRestricted() && params_.scattering_mu_s_split == 0; }
  // Whether the orders are gathered on another grid than the table's, so
  // that the table's higher orders come from one gather of their summed
  // densities at the end.
  bool GatherAtEnd() const { return settings_.higher_order_divisor > 1 || !TableOnAtmosphereGrid(); }
  // Single scattering on the atmosphere's grid, the light of order 1.
  const SingleScattering& GridSingle() const { return TableOnAtmosphereGrid() ? single_ : grid_single_; }
  // The scattering table: single Rayleigh plus the higher orders, in the
  // memory of `storage` (a texture no longer needed) where it is large
  // enough.
  Texture ScatteringTable(Texture storage = {}) const;
  // Where the range of nu that a texel's (mu, mu_s) allow ends inside a nu
  // slice interval, the slice past the range holds the light at the range's
  // edge (its clamped nu), and GetScattering, which blends two slices at
  // nu's position on the slice grid, would read the edge short of it. This
  // gives each such slice the value to which GetScattering's blend between
  // the two ends of the allowed part of its interval extends (linear, or
  // geometric for a low sun as in SunCosineMix), so that the lookup returns
  // the light at the edge and follows its change toward it. Below the
  // split (`own`: the suns there) each slice's range is that of its
  // texel's own sun. `edge_value`: the light a clamped texel (x, y, z) with
  // clamped nu stands for, in the units the lookup blends (none: the
  // texel's own value).
  static void ExtendSlicesPastTheirRange(
      const AtmosphereParameters& grid, const OwnColumnSuns* own, Texture& table,
      const std::function<vec3(int x, int y, int z, double nu)>& edge_value = nullptr);
  // Intervals with less than this fraction of them allowed keep their
  // slices; an extended slice holds at most kLargestExtension times the
  // light at the larger end of the allowed part (on Earth the cap holds
  // back 0.5 % of the single Mie table's extended values, and none of the
  // scattering table's).
  static constexpr double kSmallestExtendedFraction = 0.125;
  // MultipleScatteringPackingFactor per nu index of a grid.
  static std::vector<double> PackingFactors(const AtmosphereParameters& grid);
  // Mean over the texels of a table on a scattering grid, each times the
  // factor of its nu index (1 where `per_nu` is empty).
  static Spectrum TableMean(const Texture& table, const AtmosphereParameters& grid, const std::vector<double>& per_nu);
  // The tables as they stand, copied (for BakeOrderSnapshot) or moved out
  // (the result).
  LutSet AssembleTables(Texture transmittance, Texture irradiance, Texture scattering, Texture single_mie) const;
  double PhaseSecondsSoFar() const;

  // The ray of a scattering texel row, sampled at n + 1 points.
  RaySamples SampleRay(const AtmosphereParameters& grid, int mu_index, int r_index, int n) const;
  // The ray from radius r in direction mu, sampled at n + 1 points.
  RaySamples SampleRay(double r, double mu, bool intersects_ground, int n) const;
  // The table holds single Rayleigh scattering phase free and the higher
  // orders divided by the Rayleigh phase, which the runtime multiplies back
  // with the query's nu. The division uses the nu of the texel's slice, not
  // the texel's clamped nu: where (mu, mu_s) allow a narrow range of nu (near
  // the zenith, where the mu axis is coarse at low altitude), every slice is
  // clamped to nearly the same geometry, and dividing by the phase at that
  // clamped nu and multiplying by the phase at the query's nu would scale the
  // smooth higher orders by up to P(1)/P(0) = 2.
  static double MultipleScatteringPackingFactor(const AtmosphereParameters& grid, int nu_index) {
    return 1.0 / glsl::RayleighPhaseFunction(GetScatteringSliceTexel(grid, nu_index, 0, 0).grid_nu);
  }

  // Radiance of scattering order `order` arriving at radius r from the
  // directions with zenith cosine mu, with the sun at mu_s, excluding light
  // reflected by the ground, as a function of nu (the cosine between the
  // direction and the sun): the table lookups that do not depend on nu are
  // done once, for all the azimuths of a ring of directions.
  class IncidentAlongNu {
   public:
    IncidentAlongNu(const Baker& baker, int order, double r, double mu, double mu_s, bool intersects_ground);
    vec3 At(double nu) const;

   private:
    const AtmosphereParameters& params_;
    bool single_;  // order 1: Rayleigh and Mie tables, phases applied here
    int nu_size_ = 0;
    std::vector<vec3> first_, second_;  // per nu slice 0 ... nu_size
  };
  // Irradiance of order `order` on the ground where the sun is at mu_s.
  vec3 GroundIrradiance(int order, double mu_s) const;
  vec3 DirectIrradiance(double r, double mu_s) const;

  Medium medium_;
  BakeSettings settings_;
  AtmosphereParameters params_;  // the tables'
  // The grid over the whole atmosphere that each order's scattering density
  // lives on: the table's, or for a table restricted to a scene's ranges
  // one with BakeSettings::ScatteringRange's sizes.
  AtmosphereParameters atmosphere_grid_;
  // The grid of each order's radiance (BakeSettings::higher_order_divisor).
  AtmosphereParameters orders_grid_;
  BakeReport report_;
  BakeProgress progress_;

  // The suns of the table's rays' own columns, where it has a split.
  std::shared_ptr<const OwnColumnSuns> own_suns_;
  // Every order's gather is along the same rays, planned once.
  std::shared_ptr<GatherPlan> orders_plan_;
  Texture transmittance_;
  Texture irradiance_;
  SingleScattering single_;       // on the table's grid
  SingleScattering grid_single_;  // on atmosphere_grid_ where the table is not on it
  Texture delta_multiple_;        // radiance of the latest order >= 2, on orders_grid_
  // J of the current order per unit scattering coefficient, on atmosphere_grid_.
  Texture scattering_density_;
  // Per r row of atmosphere_grid_, the phases' weights on the scattering
  // density's sphere rule (computed with the first order's density, kept
  // for the later ones unless they are large: ComputeScatteringDensity).
  std::vector<std::unique_ptr<RingPhaseMeans>> density_phase_;
  // Sum over the orders >= 2 so far, and their tail, of their radiance, or
  // of their J where GatherAtEnd(); on atmosphere_grid_.
  Texture higher_orders_;
  Texture delta_irradiance_;      // ground irradiance of the latest order >= 2
};

}  // namespace skybake::detail
