#include "cli/bake_settings_options.h"

#include <exception>

#include <CLI/CLI.hpp>

#include "bake/errors.h"

namespace skybake::cli {

namespace {

// --orders: a count, or "auto" (0 in BakeSettings).
int ParseOrders(const std::string& text) {
  if (text == "auto") return 0;
  std::size_t end = 0;
  int orders = -1;
  try {
    orders = std::stoi(text, &end);
  } catch (const std::exception&) {
    end = 0;
  }
  if (end == 0 || end != text.size()) throw UsageError("--orders: '" + text + "' is neither a count nor auto");
  if (orders < 1) throw InputError("orders = " + text + " must be in [1, 100] or auto");
  return orders;
}

}  // namespace

void BakeSettingsOptions::AddTo(CLI::App* cmd) {
  cmd->add_option("--orders", orders,
                  "Scattering orders computed (1 = single scattering), the rest extrapolated as a geometric tail "
                  "(see --no-tail); or auto: until the estimated remaining error is below --order-tolerance")
      ->capture_default_str();
  cmd->add_option("--order-tolerance", settings.order_tolerance,
                  "--orders auto: relative size of the orders not computed")
      ->capture_default_str();
  cmd->add_option("--max-orders", settings.max_orders, "--orders auto: most orders computed")->capture_default_str();
  cmd->add_flag("--no-tail", no_tail,
                "With a count of orders: hold exactly that many, without the extrapolated tail of the orders not "
                "computed");
  cmd->add_option("--transmittance-size", transmittance_size, "Transmittance table: MU R (default 256 64)")
      ->expected(2);
  cmd->add_option("--irradiance-size", irradiance_size, "Irradiance table: MU_S R (default 64 16)")->expected(2);
  cmd->add_option("--scattering-size", scattering_size, "Scattering table: R MU MU_S NU (default 32 128 32 8; MU even)")
      ->expected(4);
  cmd->add_option("--transmittance-samples", settings.transmittance_samples,
                  "Quadrature nodes per optical-depth integral")
      ->capture_default_str();
  cmd->add_option("--ray-samples", settings.ray_samples, "Intervals per ray for inscattering integrals")
      ->capture_default_str();
  cmd->add_option("--sphere-samples", settings.sphere_samples,
                  "Polar directions for integrals over the sphere (azimuths: twice as many)")
      ->capture_default_str();
  cmd->add_option("--higher-order-divisor", settings.higher_order_divisor,
                  "Orders >= 2 on a grid with the scattering r and mu sizes divided by this (1 = full)")
      ->capture_default_str();
  cmd->add_flag("--pack-mie", settings.pack_single_mie_in_alpha,
                "Store single Mie's red channel in the scattering table's alpha instead of a separate table");
  cmd->add_option("--threads", settings.threads, "Worker threads (0 = all cores)")->capture_default_str();
}

BakeSettings BakeSettingsOptions::Resolve() const {
  BakeSettings s = settings;
  s.orders = ParseOrders(orders);
  s.extrapolate_tail = !no_tail;
  if (!transmittance_size.empty()) {
    s.transmittance_width = transmittance_size[0];
    s.transmittance_height = transmittance_size[1];
  }
  if (!irradiance_size.empty()) {
    s.irradiance_width = irradiance_size[0];
    s.irradiance_height = irradiance_size[1];
  }
  if (!scattering_size.empty()) {
    s.scattering_r_size = scattering_size[0];
    s.scattering_mu_size = scattering_size[1];
    s.scattering_mu_s_size = scattering_size[2];
    s.scattering_nu_size = scattering_size[3];
  }
  s.Validate();
  return s;
}

}  // namespace skybake::cli
