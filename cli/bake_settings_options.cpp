#include "cli/bake_settings_options.h"

#include <unistd.h>

#include <cstdio>
#include <exception>
#include <initializer_list>
#include <string>

#include <CLI/CLI.hpp>

#include "bake/spectral.h"
#include "core/errors.h"

namespace skybake::cli {

namespace {

constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

// "32 128 32 8": table sizes as the options spell them.
std::string SizeList(std::initializer_list<int> values) {
  std::string text;
  for (int v : values) text += (text.empty() ? "" : " ") + std::to_string(v);
  return text;
}

std::string ScatteringSize(const BakeSettings& s) {
  return SizeList({s.scattering_r_size, s.scattering_mu_size, s.scattering_mu_s_size, s.scattering_nu_size});
}

double PhysicalMemoryBytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? double(pages) * double(page_size) : 0.0;
}

// --orders: a count, or "auto", also spelt 0 as in BakeSettings.
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
  if (orders < 0) throw UsageError("--orders: " + text + " must be in [1, 100] or auto (0)");
  return orders;
}

}  // namespace

void BakeSettingsOptions::AddTo(CLI::App* cmd) {
  command_ = cmd;
  cmd->add_flag("--preview", preview,
                "A bake for live editing, about a twentieth of the default's time (earth: 0.12 s on 2 cores): "
                "tables T 128x32, E 32x8, S 16x64x16x4, 16 transmittance samples, 32 ray samples, 8 sphere "
                "samples; earth's daylight radiance within about 1.2 % RMS of the reference, twilight 5-16 % "
                "(docs/benchmark.md); the options given beside it override its values");
  cmd->add_option("--orders", orders,
                  "Scattering orders computed (1 = single scattering); from 4 orders on, the rest extrapolated as a "
                  "geometric tail (see --no-tail); or auto (also 0): until the estimated remaining error is below "
                  "--order-tolerance")
      ->capture_default_str();
  cmd->add_option("--order-tolerance", settings.order_tolerance,
                  "--orders auto: relative size of the orders not computed")
      ->capture_default_str();
  cmd->add_option("--max-orders", settings.max_orders, "--orders auto: most orders computed")->capture_default_str();
  cmd->add_flag("--no-tail", no_tail,
                "With a count of orders: hold exactly that many, without the extrapolated tail of the orders not "
                "computed");
  // The defaults are this command's (stress bakes smaller tables than bake).
  const BakeSettings& d = settings;
  cmd->add_option("--transmittance-size", transmittance_size,
                  "Transmittance table: MU R (default " + SizeList({d.transmittance_width, d.transmittance_height}) +
                      ")")
      ->expected(2);
  cmd->add_option("--irradiance-size", irradiance_size,
                  "Irradiance table: MU_S R (default " + SizeList({d.irradiance_width, d.irradiance_height}) + ")")
      ->expected(2);
  cmd->add_option("--scattering-size", scattering_size,
                  "Scattering table: R MU MU_S NU (default " + ScatteringSize(d) + "; MU even)")
      ->expected(4);
  cmd->add_option("--transmittance-samples", settings.transmittance_samples,
                  "Quadrature nodes per optical-depth integral")
      ->capture_default_str();
  cmd->add_option("--ray-samples", settings.ray_samples, "Intervals per ray for inscattering integrals")
      ->capture_default_str();
  cmd->add_option("--sphere-samples", settings.sphere_samples,
                  "Polar directions for integrals over the sphere (azimuths: twice as many), and half as many again in the band just above the horizon")
      ->capture_default_str();
  cmd->add_option("--higher-order-divisor", settings.higher_order_divisor,
                  "Orders >= 2 on a grid with the scattering r and mu sizes divided by this (1 = full)")
      ->capture_default_str();
  cmd->add_flag("--pack-mie", settings.pack_single_mie_in_alpha,
                "Store single Mie's red channel in the scattering table's alpha instead of a separate table");
  cmd->add_option("--threads", settings.threads,
                  "Worker threads (0 = all cores; at most " + std::to_string(kMaxThreads) + ")")
      ->capture_default_str();
}

BakeSettings BakeSettingsOptions::Resolve() const {
  BakeSettings s = settings;
  if (preview) {
    // The preview's values where the command line gives none; the sizes
    // given below replace them as they replace the defaults.
    const auto given = [&](const char* option) { return command_ != nullptr && command_->count(option) > 0; };
    s = PreviewBakeSettings(s);
    if (given("--transmittance-samples")) s.transmittance_samples = settings.transmittance_samples;
    if (given("--ray-samples")) s.ray_samples = settings.ray_samples;
    if (given("--sphere-samples")) s.sphere_samples = settings.sphere_samples;
  }
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
  // Out-of-range values are option values, so usage errors, as CLI11's own.
  try {
    s.Validate();
  } catch (const InputError& e) {
    throw UsageError(std::string("bake settings: ") + e.what());
  }
  // Refused before anything is allocated: a bake that cannot fit in memory.
  const double needed = EstimatedBakeBytes(s), available = PhysicalMemoryBytes();
  if (available > 0.0 && needed > available) {
    char text[160];
    std::snprintf(text, sizeof text, "the bake would need about %.1f GiB, more than this machine's %.1f GiB",
                  needed / kGiB, available / kGiB);
    throw UsageError("--scattering-size " + ScatteringSize(s) + ": " + text);
  }
  return s;
}

void CheckWavelengthsOption(int wavelengths) {
  if (wavelengths == 0) return;
  try {
    SpectralWavelengths(wavelengths);
  } catch (const InputError& e) {
    throw UsageError(std::string("--wavelengths: ") + e.what());
  }
}

}  // namespace skybake::cli
