#include "formats/settings_record.h"

#include <cstdio>

namespace skybake {

using nlohmann::ordered_json;

ordered_json SettingsJson(const BakeSettings& s, SettingsFields fields, int orders_used) {
  const ordered_json orders = s.orders == 0 ? ordered_json("auto") : ordered_json(s.orders);
  const ordered_json transmittance = {s.transmittance_width, s.transmittance_height};
  const ordered_json irradiance = {s.irradiance_width, s.irradiance_height};
  const ordered_json scattering = {s.scattering_r_size, s.scattering_mu_size, s.scattering_mu_s_size,
                                   s.scattering_nu_size};
  switch (fields) {
    case SettingsFields::kManifest:
      // "orders" is what was asked for (a count or "auto"), "orders_used" what
      // the tables hold, "extrapolate_tail" whether they add the orders not computed.
      return {{"orders", orders},
              {"orders_used", orders_used},
              {"extrapolate_tail", s.extrapolate_tail},
              {"transmittance_samples", s.transmittance_samples},
              {"ray_samples", s.ray_samples},
              {"sphere_samples", s.sphere_samples},
              {"higher_order_divisor", s.higher_order_divisor},
              {"pack_single_mie_in_alpha", s.pack_single_mie_in_alpha}};
    case SettingsFields::kBakeReport:
      return {{"orders", orders},
              {"order_tolerance", s.order_tolerance},
              {"tables",
               {{"transmittance", transmittance},
                {"irradiance", irradiance},
                {"scattering", scattering},
                {"single_mie_scattering", s.pack_single_mie_in_alpha ? ordered_json(nullptr) : scattering}}},
              {"samples",
               {{"transmittance", s.transmittance_samples}, {"ray", s.ray_samples}, {"sphere", s.sphere_samples}}},
              {"higher_order_divisor", s.higher_order_divisor}};
    case SettingsFields::kReportRow:
      return {{"transmittance_size", transmittance},
              {"irradiance_size", irradiance},
              {"scattering_size", scattering},
              {"orders", orders},
              {"ray_samples", s.ray_samples},
              {"sphere_samples", s.sphere_samples},
              {"higher_order_divisor", s.higher_order_divisor}};
  }
  return {};
}

std::string DescribeSettings(const BakeSettings& s, SettingsDetail detail) {
  char text[200];
  int n = std::snprintf(text, sizeof text, "T %dx%d, E %dx%d, S %dx%dx%dx%d, ", s.transmittance_width,
                        s.transmittance_height, s.irradiance_width, s.irradiance_height, s.scattering_r_size,
                        s.scattering_mu_size, s.scattering_mu_s_size, s.scattering_nu_size);
  std::string out(text, n);
  if (detail == SettingsDetail::kOrdersAndThreads) {
    out += std::to_string(s.orders) + " orders, ";
    out += s.threads > 0 ? std::to_string(s.threads) + " threads" : std::string("all cores");
  } else {
    std::snprintf(text, sizeof text, "%d ray / %d sphere samples, orders >= 2 at 1/%d", s.ray_samples,
                  s.sphere_samples, s.higher_order_divisor);
    out += text;
  }
  return out;
}

}  // namespace skybake
