// The CPU bake: from a resolved Atmosphere to the lookup tables of Bruneton &
// Neyret 2008 (transmittance, ground irradiance, 4D inscattering with all
// orders, single Mie), integrated in double precision and stored as float.
#pragma once

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "bake/scene.h"
#include "shaders_runtime/glsl_shim.h"

namespace skybake {

// The part of the scattering tables' domain a scene's bake covers
// (PlanScene in bake/scene.h): the altitudes and sun cosines the scene
// shows. The light reaching those texels comes from the whole atmosphere,
// so the orders are computed on a grid over all of it, of the table's nu
// size and these other sizes, whose single scattering takes
// `atmosphere_ray_samples` intervals per ray; the table's texels gather
// their higher orders from it.
struct ScatteringRange {
  double altitude_min_m = 0.0, altitude_max_m = 0.0;  // above the ground
  double mu_s_min = -1.0, mu_s_max = 1.0;
  int atmosphere_r_size = 32;
  int atmosphere_mu_size = 128;
  int atmosphere_mu_s_size = 16;
  int atmosphere_ray_samples = 32;
};

// The most worker threads a bake takes. It never runs more than the
// machine's hardware threads (oneTBB's arena has one slot each), so a larger
// count can only be a mistake; 1024 is above the hardware threads of the
// largest machines today (two 192-core sockets with two threads a core: 768).
inline constexpr int kMaxThreads = 1024;

struct BakeSettings {
  // Table sizes. The scattering mu size must be even (two halves: rays that
  // hit the ground and rays that do not).
  int transmittance_width = 256;  // mu
  int transmittance_height = 64;  // r
  int irradiance_width = 64;      // mu_s
  int irradiance_height = 16;     // r
  int scattering_r_size = 32;
  int scattering_mu_size = 128;
  int scattering_mu_s_size = 32;
  int scattering_nu_size = 8;
  // Scattering orders: 1 = single scattering only; 0 = auto: iterate until
  // the estimated remaining sum of all higher orders is below
  // `order_tolerance` relative to the table, at most `max_orders`, adding the
  // extrapolated geometric tail of the orders not computed (docs/stability.md).
  int orders = 4;
  double order_tolerance = 1e-4;
  int max_orders = 100;
  // With a fixed order count N, add the extrapolated geometric tail of the
  // orders not computed once the last orders decay geometrically: with q the
  // ratio of successive orders, L_(N+1) + L_(N+2) + ... = L_N q / (1 - q)
  // (its size for Earth: docs/accuracy.md); off, the tables hold exactly
  // `orders` orders (to compare with a capped reference).
  bool extrapolate_tail = true;
  // Integration: Gauss-Legendre nodes per optical-depth integral, intervals
  // per ray for the inscattering integrals, and polar directions for the
  // integrals over the sphere (twice as many azimuths).
  // Single scattering takes `ray_samples` intervals per ray; the higher
  // orders, whose source along the ray is smooth, half as many but not
  // fewer than 32 (too few intervals let an optically thick haze overshoot
  // the energy bound, stress_fuzz_test) or all where there are fewer. Single
  // scattering keeps them all: its source has the edge of the planet's
  // shadow, and near the horizon half as many miss the brute-force integral
  // by more than SingleScattering.MatchesBruteForceQuadratureWithinHalfPercent
  // allows (docs/benchmark.md).
  int transmittance_samples = 64;
  int ray_samples = 128;
  int sphere_samples = 16;
  // Above 1, each order >= 2 is gathered from its scattering density on a
  // grid with the r and mu sizes of the densities' grid (the table's, or
  // ScatteringRange's) divided by this, as the radiance the next order
  // scatters (which an integral over the sphere smooths), and the densities
  // of all orders, on their grid, are summed and gathered once along the
  // table's own rays. Faster, at a small error for thin atmospheres, but
  // optically thick ones lose light order after order, so the default keeps
  // every order on the table's grid (docs/benchmark.md has both).
  int higher_order_divisor = 1;
  // Restricts the scattering tables to a scene's altitudes and suns; unset,
  // they cover the atmosphere and every sun down to its mu_s_min.
  std::optional<ScatteringRange> scattering_range;
  // Store single Mie's red channel in the scattering table's alpha instead of
  // a separate table (Bruneton 2017's approximation, halves the memory).
  bool pack_single_mie_in_alpha = false;
  // With orders = 1: the irradiance table also holds single scattering's
  // light on the ground (what the second order's indirect irradiance adds).
  bool single_scattering_sky_irradiance = false;
  // Worker threads; 0 = all cores; at most kMaxThreads.
  int threads = 0;

  // InputError naming the setting if a value is out of range.
  void Validate() const;
};

// The peak memory a bake with these settings takes, in bytes, from a fit of
// measured peaks (docs/benchmark.md): a fixed part plus a part proportional to
// the 4D tables' texels, rounded up.
double EstimatedBakeBytes(const BakeSettings& settings);

// The preview bake (`skybake bake --preview`), for live editing: the default
// orders and tail on smaller tables (T 128x32, E 32x8, S 16x64x16x4) and
// fewer integration samples (16 optical-depth nodes, 32 ray intervals, 8
// polar directions), about a twentieth of the default bake's time; its error
// per case group against the reference is in docs/benchmark.md. `settings`
// with those sizes and samples, its other settings kept.
BakeSettings PreviewBakeSettings(BakeSettings settings = {});

// The colour of a spectral bake (bake/spectral.h): its tables hold CIE 1931
// XYZ in photometric units (Y in cd m^-2, lux for irradiance) of the
// spectrum sampled at these wavelengths instead of one wavelength per channel.
struct SpectralColour {
  std::vector<double> wavelengths_nm;
  // Those at which the scattering orders >= 2 were computed; at the others
  // they are interpolated (bake/spectral.h).
  std::vector<double> higher_order_wavelengths_nm;
};

// The baked tables and the constants the runtime needs to sample them.
struct LutSet {
  Atmosphere atmosphere;
  BakeSettings settings;
  // Scattering orders the tables hold (settings.orders is 0 for auto);
  // an extrapolated tail of further orders may be added on top.
  int orders_used = 0;
  glsl::AtmosphereParameters parameters;
  glsl::Texture transmittance;  // 2D, rgb = optical depth to the top boundary
  glsl::Texture irradiance;     // 2D, rgb = indirect ground irradiance
  glsl::Texture scattering;     // 3D, rgb = single Rayleigh + all higher orders / Rayleigh phase;
                                // alpha = single Mie red if packed
  glsl::Texture single_mie_scattering;  // 3D, rgb; empty if packed
  // The scene the set was baked for, if any: its tables are those
  // PlanScene keeps (formats/lut_tables.h lists only those).
  std::optional<Scene> scene;
  // Set for a spectral bake: the channels are X, Y, Z, not the atmosphere's
  // wavelengths.
  std::optional<SpectralColour> colour;
};

struct BakeTiming {
  std::string phase;
  double seconds = 0.0;
};

struct BakeReport {
  std::vector<BakeTiming> timings;  // in the order the phases ran
  double total_seconds = 0.0;
  // Scattering orders computed, the ratio of the last two orders' sizes (0
  // if fewer than three orders), the extrapolated tail added to the tables
  // and the estimated remaining error, both relative to the scattering table
  // (largest over the channels; see docs/stability.md).
  int orders_used = 0;
  double order_ratio = 0.0;
  double extrapolated_tail = 0.0;
  double remaining_error = 0.0;
};

// Called after each phase with its name and duration.
using BakeProgress = std::function<void(const BakeTiming&)>;

// `take` is called once single scattering is done (order 1) and after each
// further order up to `last_order` with the tables a bake of exactly that
// many orders returns (before any extrapolated tail) and the seconds the
// bake's phases took so far, so that one bake yields every order up to
// `orders` (`skybake report`). Each snapshot builds and copies every table.
struct BakeOrderSnapshot {
  std::function<void(int order, const LutSet& tables, double bake_seconds)> take;
  int last_order = std::numeric_limits<int>::max();
};

LutSet Bake(const Atmosphere& atmosphere, const BakeSettings& settings, BakeReport* report = nullptr,
            const BakeProgress& progress = nullptr, const BakeOrderSnapshot& order_snapshot = {});

// The physical coordinates a scattering texel stands for. Texel
// (x = nu_index * mu_s_size + mu_s_index, y = mu_index, z = r_index) sits at
// the centre of its (mu_s, mu, r) cell and on the nu grid (nu = -1 .. 1
// inclusive); `nu` is clamped to the range (mu, mu_s) allow, `grid_nu` is not.
struct ScatteringTexel {
  double r = 0.0, mu = 0.0, mu_s = 0.0, nu = 0.0, grid_nu = 0.0;
  bool ray_intersects_ground = false;
};
ScatteringTexel GetScatteringTexel(const glsl::AtmosphereParameters& parameters, int x, int y, int z);
// The texel of nu slice nu_index and row (y, z) at the highest mu_s column,
// whose sun is the same for every ray: for a caller that needs the ray (r,
// mu) or the slice's nu, without the fixed point that finds the sun of a
// column below the split.
ScatteringTexel GetScatteringSliceTexel(const glsl::AtmosphereParameters& parameters, int nu_index, int y, int z);
// A slice whose grid nu lies past the range its (mu, mu_s) allow holds, in
// the tables as written, the light to which the lookup's blend extends from
// the allowed part of its interval, at most this many times the light there.
inline constexpr double kLargestExtension = 2.0;
// nu clamped to the range that the view and sun cosines mu and mu_s allow.
double ClampedNu(double nu, double mu, double mu_s);

// The scattering coefficients at the ground of the Mie constituents (those
// whose single scattering the tables keep apart, Medium::mie_group) and of
// all the others.
void GroundScatteringOfMieAndOthers(const Atmosphere& atmosphere, Spectrum* mie, Spectrum* others);

// The runtime constants for an atmosphere and table sizes (also used by
// loaders that rebuild a LutSet from files).
glsl::AtmosphereParameters MakeAtmosphereParameters(const Atmosphere& atmosphere, const BakeSettings& settings);

// The grid over the whole atmosphere a bake computes the scattering orders
// on: the tables' r, mu and nu rows unless settings.scattering_range
// restricts them, and mu_s columns at the same suns for every ray (the
// scattering density J, light arriving at a point, has no shadow edge to
// follow; shadow_edge.glsl, "The sun axis after sunset").
glsl::AtmosphereParameters AtmosphereGrid(const Atmosphere& atmosphere, const BakeSettings& settings);

// Fills the coefficient profiles of `parameters` (definitions.glsl) from the
// atmosphere; MakeAtmosphereParameters does it, and so must a loader that
// reads the other parameters from a manifest.
void SetAltitudeProfiles(const Atmosphere& atmosphere, glsl::AtmosphereParameters* parameters);

}  // namespace skybake

namespace skybake {
// The tables of a LutSet as the twin samples them (the LutSet must outlive it).
struct TwinTables;
TwinTables MakeTwinTables(const LutSet& luts);
}  // namespace skybake
