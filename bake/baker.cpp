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
    if (order_snapshot) {
      LutSet tables = AssembleTables(transmittance_, irradiance_, ScatteringTable(), single_.mie);
      tables.settings.orders = order;  // exactly these orders, no tail
      tables.settings.extrapolate_tail = false;
      order_snapshot(order, tables, PhaseSecondsSoFar());
    }
  };
  auto start = std::chrono::steady_clock::now();
  const BakeSettings& s = settings_;
  transmittance_ = Texture(s.transmittance_width, s.transmittance_height);
  irradiance_ = Texture(s.irradiance_width, s.irradiance_height);

  Phase("transmittance", [&] { ComputeTransmittance(); });
  Phase("single scattering", [&] { single_ = ComputeSingleScattering(params_, s.ray_samples); });
  if (s.orders != 1 && TableRestricted()) {
    // It feeds only the next order, through an integral over the sphere.
    Phase("single scattering, whole atmosphere", [&] {
      grid_single_ = ComputeSingleScattering(atmosphere_grid_, s.scattering_range->atmosphere_ray_samples);
    });
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
  sums.table = TableMean(GridSingle().rayleigh, atmosphere_grid_, {});
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
      // its own fall. The later orders are gathered linearly: weights that
      // depend on each order's values would make the orders' operator
      // nonlinear, and the extrapolated tail then misses by more than 1 %
      // (Orders.AutoWithTail... on the stiff slab; docs/accuracy.md).
      const MuSFall fall = order == 2 ? MuSFallOf(scattering_density_) : MuSFall();
      delta_multiple_ = GatherAlongRays(orders_grid_, scattering_density_, atmosphere_grid_,
                                        order == 2 ? &fall : nullptr);
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
  Texture scattering;
  if (gather_at_end) {
    Phase("gather higher orders", [&] { scattering = ScatteringTable(); });
  } else {
    scattering = ScatteringTable();
  }

  LutSet result = AssembleTables(std::move(transmittance_), std::move(irradiance_), std::move(scattering),
                                 std::move(single_.mie));
  report_.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = report_;
  return result;
}

Texture Baker::ScatteringTable() const {
  Texture table = single_.rayleigh;
  if (report_.orders_used < 2) return table;
  const Texture higher = GatherAtEnd() ? GatherAlongRays(params_, higher_orders_, atmosphere_grid_) : higher_orders_;
  const int mu_s_size = params_.scattering_mu_s_size;
  const std::vector<double> packing = PackingFactors(params_);
  ForEachRow(table, [&](int, std::size_t first, std::size_t end) {
    for (std::size_t i = first; i < end; i += 4) {
      const double factor = packing[(i - first) / 4 / mu_s_size];
      for (int c = 0; c < 3; ++c) table.texels[i + c] += float(higher.texels[i + c] * factor);
    }
  });
  return table;
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
