// `skybake stress`: bakes the stress set (bake/stress_set.h) and the built-in
// presets at small table sizes and checks the invariants of
// bake/invariants.h and the energy balance, one line per atmosphere.
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "bake/stress_set.h"
#include "cli/bake_settings_options.h"
#include "cli/commands.h"
#include "core/errors.h"

namespace skybake::cli {

namespace {

struct StressOptions {
  std::vector<std::string> atmospheres;  // files or presets; empty: the stress set and every preset
  BakeSettingsOptions bake;
  std::vector<std::string> only;
  int queries = 100000;
  std::uint64_t seed = 7;
  bool json = false;
  bool resolution_given = false;  // --scattering-size or --sphere-samples on the command line
};

std::string Triple(const Spectrum& v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.4f %.4f %.4f", v.x, v.y, v.z);
  return buffer;
}

nlohmann::json ToJson(const std::string& name, const StressResult& r) {
  auto spectrum = [](const Spectrum& v) { return nlohmann::json::array({v.x, v.y, v.z}); };
  return {{"atmosphere", name},
          {"orders_used", r.bake.orders_used},
          {"order_ratio", r.bake.order_ratio},
          {"extrapolated_tail", r.bake.extrapolated_tail},
          {"remaining_error", r.bake.remaining_error >= 0.0 ? nlohmann::json(r.bake.remaining_error)
                                                            : nlohmann::json(nullptr)},
          {"values_checked", r.tables.values_checked + r.queries.values_checked},
          {"violations", r.Violations()},
          {"examples", r.tables.examples.empty() ? r.queries.examples : r.tables.examples},
          {"largest_transmittance_increase", r.queries.largest_transmittance_increase},
          {"largest_direction_difference", r.queries.largest_direction_difference},
          {"energy_out", spectrum(r.energy.Outgoing())},
          {"energy_scattered", spectrum(r.energy.scattered)},
          {"energy_transmitted", spectrum(r.energy.transmitted)},
          {"energy_uncovered_area", r.energy.uncovered_area},
          {"energy_balanced", r.energy_balanced},
          {"seconds", r.seconds}};
}

void RunStressCommand(const StressOptions& o) {
  if (o.queries < 0) throw InputError("queries = " + std::to_string(o.queries) + " must be >= 0");
  const BakeSettings settings = o.bake.Resolve();
  if (!o.atmospheres.empty() && !o.only.empty()) {
    throw UsageError("--only: chooses from the built-in set; give either atmospheres or --only");
  }
  std::vector<StressAtmosphere> set;
  if (o.atmospheres.empty()) {
    set = StressSet();
    for (const PresetInfo& preset : ListPresets()) set.push_back(StressAtmosphere{LoadPreset(preset.name), false});
  }
  // A user's own atmospheres get every check but the energy balance, which
  // only closes for the white-ground case the stress set builds for it.
  for (const std::string& atmosphere : o.atmospheres) {
    set.push_back(StressAtmosphere{LoadAtmosphere(atmosphere), false});
  }
  if (!o.only.empty()) {
    std::vector<StressAtmosphere> chosen;
    for (const std::string& name : o.only) {
      auto match = std::find_if(set.begin(), set.end(), [&](const auto& s) { return s.atmosphere.name == name; });
      if (match == set.end()) throw UsageError("--only: no stress atmosphere or preset named '" + name + "'");
      chosen.push_back(*match);
    }
    set = chosen;
  }

  if (!o.json) {
    std::printf("%-22s %6s %10s %12s %14s  %-20s %8s\n", "atmosphere", "orders", "remaining", "violations",
                "values", "energy out (r g b)", "time");
  }
  nlohmann::json report = nlohmann::json::array();
  std::int64_t violations = 0;
  int failed = 0;
  for (const StressAtmosphere& stress : set) {
    StressResult r = RunStress(
        stress, o.resolution_given ? settings : WithEnergyBalanceResolution(stress, settings), o.queries, o.seed);
    violations += r.Violations();
    failed += r.Violations() > 0;
    if (o.json) {
      report.push_back(ToJson(stress.atmosphere.name, r));
      continue;
    }
    char remaining[32] = "unknown";
    if (r.bake.remaining_error >= 0.0) std::snprintf(remaining, sizeof remaining, "%.2g", r.bake.remaining_error);
    std::printf("%-22s %6d %10s %12lld %14lld  %-20s %7.2fs%s\n", stress.atmosphere.name.c_str(),
                r.bake.orders_used, remaining, static_cast<long long>(r.Violations()),
                static_cast<long long>(r.tables.values_checked + r.queries.values_checked),
                Triple(r.energy.Outgoing()).c_str(), r.seconds,
                stress.must_balance_energy ? (r.energy_balanced ? "  (balances)" : "  (DOES NOT BALANCE)") : "");
    for (const std::string& e : r.tables.examples) std::printf("    %s\n", e.c_str());
    for (const std::string& e : r.queries.examples) std::printf("    %s\n", e.c_str());
    std::fflush(stdout);
  }
  if (o.json) std::printf("%s\n", report.dump(2).c_str());
  if (violations > 0) {
    throw InternalError("stress: " + std::to_string(violations) + " invariant violations in " +
                        std::to_string(failed) + " atmospheres");
  }
}

}  // namespace

void AddStressCommand(CLI::App& app) {
  auto o = std::make_shared<StressOptions>();
  CLI::App* cmd = app.add_subcommand(
      "stress",
      "Bake atmospheres at small tables (orders auto) and check the invariants on every texel and twin query; "
      "without atmospheres, the stress set and the presets, with the energy balance of the white-ground case "
      "(its tables at least 64 mu, 64 mu_s and 16 sphere samples unless --scattering-size or --sphere-samples "
      "is given)");
  cmd->add_option("atmosphere", o->atmospheres,
                  "Atmosphere files (.toml; - for standard input) or preset names (preset:NAME) to check instead");
  o->bake.settings = StressBakeSettings();
  o->bake.orders = "auto";
  o->bake.AddTo(cmd);
  cmd->add_option("--only", o->only, "Run only these atmospheres (stress set or preset names)");
  cmd->add_option("--queries", o->queries, "Random twin queries per atmosphere")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the random queries")->capture_default_str();
  cmd->add_flag("--json", o->json, "Print the results as JSON on stdout");
  cmd->callback([o, cmd] {
    o->resolution_given = cmd->count("--scattering-size") + cmd->count("--sphere-samples") > 0;
    RunStressCommand(*o);
  });
}

}  // namespace skybake::cli
