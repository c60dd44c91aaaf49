// The bake's passes in order: transmittance, single scattering, then per
// order the scattering density, the indirect irradiance and the gathered
// radiance, until the orders converge or their count is reached.
#include "bake/baker.h"

#include <chrono>
#include <optional>
#include <string>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/parallel_for.h>

#include "bake/grids.h"
#include "bake/order_convergence.h"
#include "core/constants.h"
#include "shaders_runtime/runtime.h"

namespace skybake::detail {
template <typename F>
void Baker::Phase(const std::string& name, F&& work) {
  auto start = std::chrono::steady_clock::now();
  work();
  BakeTiming timing{name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  report_.timings.push_back(timing);
  if (progress_) progress_(timing);
}

LutSet Baker::AssembleTables(Texture transmittance, Texture irradiance, Texture scattering,
                             Texture single_mie) const {
  LutSet result;
  result.atmosphere = medium_.atmosphere();
  result.settings = settings_;
  result.orders_used = report_.orders_used;
  result.parameters = params_;
  result.transmittance = std::move(transmittance);
  result.irradiance = std::move(irradiance);
  ExtendSlicesPastTheirRange(params_, own_suns_.get(), single_mie);
  if (params_.single_mie_in_scattering_alpha == 1) {
    for (size_t i = 0; i < scattering.texels.size(); i += 4) scattering.texels[i + 3] = single_mie.texels[i];
  } else {
    result.single_mie_scattering = std::move(single_mie);
  }
  result.scattering = std::move(scattering);
  return result;
}

double Baker::PhaseSecondsSoFar() const {
  double seconds = 0.0;
  for (const BakeTiming& t : report_.timings) seconds += t.seconds;
  return seconds;
}

LutSet Baker::Run(BakeReport* report, const BakeProgress& progress, const BakeOrderSnapshot& order_snapshot) {
  progress_ = progress;
  auto snapshot = [&](int order) {
    if (order_snapshot.take && order <= order_snapshot.last_order) {
      LutSet tables = AssembleTables(transmittance_, irradiance_, ScatteringTable(), single_.mie);
      tables.settings.orders = order;  // exactly these orders, no tail
      tables.settings.extrapolate_tail = false;
      order_snapshot.take(order, tables, PhaseSecondsSoFar());
    }
  };
  auto start = std::chrono::steady_clock::now();
  const BakeSettings& s = settings_;
  transmittance_ = Texture(s.transmittance_width, s.transmittance_height);
  irradiance_ = Texture(s.irradiance_width, s.irradiance_height);

  Phase("transmittance", [&] { ComputeTransmittance(); });
  // The orders' grid needs single scattering (for the next order and the
  // sky irradiance, through integrals over the sphere) at its columns with
  // mu_s >= LOW_SUN_MU_S (below them they integrate it along their rings:
  // RingSingleScattering). Where it is not the table's grid but has its
  // rows, that is the table's from the split up and the rest is computed
  // along the table's rays; else on the grid itself.
  const bool grid_single = (s.orders != 1 || s.single_scattering_sky_irradiance) && !TableOnAtmosphereGrid();
  if (params_.scattering_mu_s_split == 0) {
    own_suns_ = nullptr;
  } else if (!own_suns_ || !own_suns_->HasTheSunsOf(params_)) {
    Phase("each ray's own sun columns", [&] { own_suns_ = std::make_shared<const OwnColumnSuns>(params_); });
  }
  Phase("single scattering", [&] {
    const SunColumns grid_columns(atmosphere_grid_);
    OtherColumns other;
    if (grid_single && !TableRestricted()) {
      other = {&grid_columns, LowSunColumnCount(grid_columns), params_.scattering_mu_s_split};
      grid_single_ = {ScatteringGridTexture(atmosphere_grid_), ScatteringGridTexture(atmosphere_grid_)};
    }
    single_ = ComputeSingleScattering(params_, s.ray_samples, own_suns_.get(), other,
                                      other.columns ? &grid_single_ : nullptr);
    if (other.columns) {
      CopyColumnsFrom(single_.rayleigh, params_, params_.scattering_mu_s_split, &grid_single_.rayleigh);
      CopyColumnsFrom(single_.mie, params_, params_.scattering_mu_s_split, &grid_single_.mie);
    }
  });
  if (grid_single && TableRestricted()) {
    Phase("single scattering, whole atmosphere", [&] {
      grid_single_ = ComputeSingleScattering(atmosphere_grid_, s.scattering_range->atmosphere_ray_samples, nullptr);
    });
  }
  if (s.orders == 1 && s.single_scattering_sky_irradiance) {
    delta_irradiance_ = Texture(s.irradiance_width, s.irradiance_height);
    Phase("sky irradiance of single scattering", [&] { ComputeIndirectIrradiance(1); });
  }
  if (s.orders != 1) {  // 0 = auto
    scattering_density_ = ScatteringGridTexture(atmosphere_grid_);
    higher_orders_ = ScatteringGridTexture(atmosphere_grid_);
    delta_irradiance_ = Texture(s.irradiance_width, s.irradiance_height);
  }
  report_.orders_used = 1;
  snapshot(1);
  report_.remaining_error = -1.0;  // unknown until two orders can be compared
  const bool auto_orders = s.orders == 0;
  OrderConvergence convergence;
  // Convergence is measured on means over the tables (each order's on its own grid).
  OrderSums sums;
  // (Where the table has the grid's rows, its own: the grid's single
  // scattering lacks the low suns.)
  sums.table = TableRestricted() ? TableMean(GridSingle().rayleigh, atmosphere_grid_, {})
                                 : TableMean(single_.rayleigh, params_, {});
  const std::vector<double> orders_packing = PackingFactors(orders_grid_);
  const bool gather_at_end = GatherAtEnd();
  for (int order = 2; order <= (auto_orders ? s.max_orders : s.orders); ++order) {
    std::string prefix = "order " + std::to_string(order) + ": ";
    Phase(prefix + "scattering density", [&] { ComputeScatteringDensity(order); });
    Phase(prefix + "indirect irradiance", [&] { ComputeIndirectIrradiance(order - 1); });
    // On the table's grid the orders themselves are summed; on a coarser
    // one, their densities, for the final gather.
    const Texture& newest = gather_at_end ? scattering_density_ : delta_multiple_;
    Phase(prefix + "multiple scattering", [&] {
      // The second order's J falls by orders of magnitude from one mu_s
      // column to the next after sunset, and along a ray into the Earth's
      // shadow the sun sinks by several columns: it is gathered following
      // its own fall. The later orders are gathered linearly between the
      // columns: weights that depend on each order's values would make the
      // orders' operator nonlinear, and the extrapolated tail then misses by
      // more than 1 % (Orders.AutoWithTail... on the stiff slab;
      // docs/accuracy.md). Below the grid's lowest sun every order's J
      // continues its own fall (held, it read the views from space into the
      // Earth's shadow tens of times too bright); only deep-shadow samples
      // read it, and the tail tests hold.
      const MuSFall fall = MuSFallOf(scattering_density_, order == 2);
      if (!orders_plan_) orders_plan_ = PlanGather(orders_grid_, nullptr, atmosphere_grid_);
      GatherAlongRays(*orders_plan_, scattering_density_, &fall, &delta_multiple_);
      AddScaled(newest, Spectrum(1.0), higher_orders_);
    });
    report_.orders_used = order;
    sums.newest = TableMean(delta_multiple_, orders_grid_, orders_packing);
    sums.table += sums.newest;
    convergence.Add(sums);
    report_.order_ratio = convergence.Ratio();
    report_.remaining_error = convergence.RemainingWithoutTail();
    snapshot(order);
    if (auto_orders && convergence.NewestIsZero()) break;
    // Auto: stop once the tail is known well enough. A fixed count: add the
    // tail after its last order, if the orders decay geometrically by then.
    std::optional<Spectrum> tail = convergence.TailFactor();
    const bool add_tail = auto_orders ? tail && convergence.TailError() < s.order_tolerance
                                      : order == s.orders && s.extrapolate_tail && tail && !convergence.NewestIsZero();
    if (add_tail) {
      // The orders not computed: the newest order's density and irradiance
      // times q / (1 - q) per channel.
      Phase("extrapolated orders", [&] {
        AddScaled(newest, *tail, higher_orders_);
        AddScaled(delta_irradiance_, *tail, irradiance_);
      });
      report_.extrapolated_tail = convergence.RelativeTail();
      report_.remaining_error = convergence.TailError();
      break;
    }
  }
  // The orders' density is no longer needed: its pages hold the table.
  Texture scattering;
  if (gather_at_end) {
    Phase("gather higher orders", [&] { scattering = ScatteringTable(std::move(scattering_density_)); });
  } else {
    scattering = ScatteringTable(std::move(scattering_density_));
  }

  LutSet result = AssembleTables(std::move(transmittance_), std::move(irradiance_), std::move(scattering),
                                 std::move(single_.mie));
  report_.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = report_;
  return result;
}

Texture Baker::ScatteringTable(Texture storage) const {
  Texture table = std::move(storage);
  table = single_.rayleigh;  // into the storage's memory if it is large enough
  if (report_.orders_used < 2) {
    ExtendSlicesPastTheirRange(params_, own_suns_.get(), table);
    return table;
  }
  Texture gathered;
  if (GatherAtEnd()) {
    // Below the split the table's texels reach far into the Earth's
    // shadow, where the summed J falls as its orders do, the second's
    // fastest: gathered there along its fall between columns and below the
    // grid's lowest sun (as the second order's own gather is; linear in J
    // it read the deep twilight several times too bright). So is a whole
    // table without a split (too few mu_s texels for one) whose orders were
    // gathered on a coarser grid: linear in J and held below the lowest
    // sun, its twilight sky at sun 101-102 degrees read about 30 times too
    // bright. A scene's restricted table keeps J linear: on a scene's
    // coarse grid of the orders the fall read its sky at sunset worse
    // (docs/accuracy.md).
    std::optional<MuSFall> fall;
    if (params_.scattering_mu_s_split > 0 || !TableRestricted()) fall = MuSFallOf(higher_orders_, true);
    // Where the table has the orders' rows, along the orders' rays.
    const bool orders_rows = !TableRestricted() && settings_.higher_order_divisor == 1;
    GatherAlongRays(orders_rows ? *PlanGatherForColumns(*orders_plan_, params_, own_suns_.get())
                                : *PlanGather(params_, own_suns_.get(), atmosphere_grid_),
                    higher_orders_, fall ? &*fall : nullptr, &gathered);
  }
  const Texture& higher = GatherAtEnd() ? gathered : higher_orders_;
  const int mu_s_size = params_.scattering_mu_s_size;
  const std::vector<double> packing = PackingFactors(params_);
  ForEachRow(table, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      const double factor = packing[(i - first) / 4 / mu_s_size];
      for (int c = 0; c < 3; ++c) table.texels[i + c] += float(higher.texels[i + c] * factor);
    }
  });
  // At a slice's clamped nu the runtime multiplies the higher orders by the
  // Rayleigh phase there, not at the slice's own nu.
  ExtendSlicesPastTheirRange(params_, own_suns_.get(), table, [&](int x, int y, int z, double nu) {
    return vec3(single_.rayleigh.Fetch(x, y, z)) + vec3(higher.Fetch(x, y, z)) / glsl::RayleighPhaseFunction(nu);
  });
  return table;
}

void Baker::ExtendSlicesPastTheirRange(const AtmosphereParameters& grid, const OwnColumnSuns* own, Texture& table,
                                       const std::function<vec3(int x, int y, int z, double nu)>& edge_value) {
  const int nu_size = grid.scattering_nu_size, mu_s_size = grid.scattering_mu_s_size;
  // Rows are independent, and within a row each slice past the range is
  // read (for its own edge value) and written once, by the interval whose
  // allowed part it extends; the slices inside the range are only read.
  const SunColumns columns(grid);
  tbb::parallel_for(0, grid.scattering_mu_size * grid.scattering_r_size, [&](int row) {
    const int y = row % grid.scattering_mu_size, z = row / grid.scattering_mu_size;
    const double mu = GetScatteringSliceTexel(grid, 0, y, z).mu;
    for (int column = 0; column < mu_s_size; ++column) {
      // Below the split each slice's texel lies at its own sun, whose range
      // of nu bounds it (the lookup there blends the slices geometrically).
      const bool own_column = column < grid.scattering_mu_s_split;
      const bool geometric = own_column || columns.mu_s[column] < glsl::LOW_SUN_MU_S;  // SunCosineMix's blend
      for (int k = 0; k + 1 < nu_size; ++k) {
        const int x0 = k * mu_s_size + column, x1 = x0 + mu_s_size;
        const double mu_s0 = own_column ? own->MuS(x0, y, z) : columns.mu_s[column];
        const double mu_s1 = own_column ? own->MuS(x1, y, z) : columns.mu_s[column];
        const double lowest = ClampedNu(-1.0, mu, mu_s0), highest = ClampedNu(1.0, mu, mu_s1);
        const double nu_k = columns.grid_nu[x0], spacing = columns.grid_nu[x1] - nu_k;
        const double start = std::max(nu_k, lowest), end = std::min(nu_k + spacing, highest);
        const bool k_clamped = start > nu_k, next_clamped = end < nu_k + spacing;
        // Intervals wholly inside or outside the range, or with too little
        // of it inside to extend from, keep their slices.
        if (!(k_clamped || next_clamped) || end - start < kSmallestExtendedFraction * spacing) continue;
        // (A texel's nu is its slice's clamped as GetScatteringTexel clamps it.)
        const vec3 at_start =
            k_clamped && edge_value ? edge_value(x0, y, z, ClampedNu(nu_k, mu, mu_s0)) : vec3(table.Fetch(x0, y, z));
        const vec3 at_end = next_clamped && edge_value ? edge_value(x1, y, z, ClampedNu(columns.grid_nu[x1], mu, mu_s1))
                                                       : vec3(table.Fetch(x1, y, z));
        const double t_start = (start - nu_k) / spacing, t_end = (end - nu_k) / spacing;
        vec4 value0 = table.Fetch(x0, y, z), value1 = table.Fetch(x1, y, z);
        for (int c = 0; c < 3; ++c) {
          if (geometric && !(at_start[c] > 0.0 && at_end[c] > 0.0)) continue;
          const double a = geometric ? std::log(at_start[c]) : at_start[c];
          const double b = geometric ? std::log(at_end[c]) : at_end[c];
          // The line through (t_start, a) and (t_end, b), at t = 0 and 1,
          // at most kLargestExtension times the larger end.
          const double slope = (b - a) / (t_end - t_start);
          const double largest = geometric ? std::max(a, b) + std::log(kLargestExtension)
                                           : kLargestExtension * std::max(a, b);
          const double v0 = std::min(a - slope * t_start, largest), v1 = std::min(b + slope * (1.0 - t_end), largest);
          if (k_clamped) value0[c] = float(geometric ? std::exp(v0) : std::max(v0, 0.0));
          if (next_clamped) value1[c] = float(geometric ? std::exp(v1) : std::max(v1, 0.0));
        }
        if (k_clamped) table.Store(x0, y, z, value0);
        if (next_clamped) table.Store(x1, y, z, value1);
      }
    }
  });
}

std::vector<double> Baker::PackingFactors(const AtmosphereParameters& grid) {
  std::vector<double> factors(grid.scattering_nu_size);
  for (int nu = 0; nu < grid.scattering_nu_size; ++nu) factors[nu] = MultipleScatteringPackingFactor(grid, nu);
  return factors;
}

Spectrum Baker::TableMean(const Texture& table, const AtmosphereParameters& grid, const std::vector<double>& per_nu) {
  const int mu_s_size = grid.scattering_mu_s_size;
  // Per row, then the rows in order: the same sum whatever the threads do.
  std::vector<Spectrum> row_sums(std::size_t(table.height) * table.depth, Spectrum(0.0));
  ForEachRow(table, [&](int row, std::size_t first, std::size_t end) {
    Spectrum sum(0.0);
    for (std::size_t i = first; i < end; i += 4) {
      const double factor = per_nu.empty() ? 1.0 : per_nu[(i - first) / 4 / mu_s_size];
      for (int c = 0; c < 3; ++c) sum[c] += table.texels[i + c] * factor;
    }
    row_sums[row] = sum;
  });
  Spectrum sum(0.0);
  for (const Spectrum& row_sum : row_sums) sum += row_sum;
  return sum / double(table.texels.size() / 4);
}

void Baker::ComputeTransmittance() {
  const int width = transmittance_.width, height = transmittance_.height;
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      double r, mu;
      glsl::GetRMuFromTransmittanceTextureUv(params_, glsl::vec2((x + 0.5) / width, (y + 0.5) / height), r, mu);
      double d = glsl::DistanceToTopAtmosphereBoundary(params_, r, mu);
      Spectrum tau = medium_.OpticalDepth(r, mu, d, settings_.transmittance_samples);
      transmittance_.Store(x, y, 0, vec4(tau, 0.0));
    }
  });
}
}  // namespace skybake::detail
