// `skybake bench`: times each phase of a bake (files written included) over
// several runs and reports medians and the peak resident memory, optionally
// with the cost of scaling the work (each table axis doubled, orders 1-8,
// 3, 15 and 45 wavelengths, 1, 2 and all threads), each with its own peak
// memory. docs/benchmark.md holds its table (scripts/bench.sh).
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "cli/bake_settings_options.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/interrupt.h"
#include "formats/settings_record.h"
#include "pipeline/bake_pipeline.h"

namespace skybake::cli {

namespace {

struct BenchOptions {
  std::string atmosphere = "earth";
  std::string output_dir;  // empty: a temporary directory, removed afterwards
  BakeSettingsOptions bake;
  int wavelengths = 0;  // as `bake --wavelengths`: 0 is the atmosphere's own three
  std::string spectral_higher_orders = ToString(kDefaultSpectralHigherOrders);
  int runs = 5;
  bool scaling = false;
  bool json = false;
};

double Median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Peak resident memory of this process since the last ResetPeakResident
// (Linux: VmHWM of /proc/self/status, in kB); getrusage's maximum as a
// fallback.
double PeakResidentMiB() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.compare(0, 6, "VmHWM:") == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// Returns the memory freed so far to the system, which the bake's allocator
// keeps otherwise (cli/main.cpp): each measured bake then faults in its
// tables' pages as the single bake of a `skybake bake` process does, instead
// of reusing the pages of the run before it (0.3 s faster, and not what a
// user sees).
void ReturnFreedMemory() { malloc_trim(0); }

// Restarts the peak resident set size at the current one (Linux's
// /proc/self/clear_refs "5"), so that each configuration's peak is its own.
void ResetPeakResident() {
  ReturnFreedMemory();
  std::ofstream("/proc/self/clear_refs") << "5";
}

// Per-phase seconds of `runs` bakes of one configuration, files written.
struct Measurement {
  std::vector<std::string> phases;                   // in the order they ran
  std::map<std::string, std::vector<double>> seconds;  // phase (and "total") -> one value per run
};

// What one configuration bakes: the settings and, as `bake --wavelengths`
// and `--spectral-higher-orders`, the number of wavelengths (0: the
// atmosphere's own three) and how their higher orders are computed.
struct BenchConfiguration {
  BakeSettings settings;
  int wavelengths = 0;
  SpectralHigherOrders spectral_higher_orders = kDefaultSpectralHigherOrders;
};

Measurement Measure(const AtmosphereSource& source, const Atmosphere& atmosphere,
                    const BenchConfiguration& configuration, int runs, const std::filesystem::path& dir,
                    const std::string& interrupt_note) {
  // The bake pipeline of `skybake bake` without the runtime: the tables
  // and the manifest, in EXR and KTX2.
  pipeline::BakeJob job;
  job.settings = configuration.settings;
  job.wavelengths = configuration.wavelengths;
  job.spectral_higher_orders = configuration.spectral_higher_orders;
  job.spectral_source = source;
  job.runtime_languages.clear();
  job.command_line = CommandLine();
  Measurement m;
  for (int run = 0; run < runs; ++run) {
    // Each run's set replaces the last one's whole (core/interrupt.h).
    SetInterruptNote(interrupt_note);
    ReturnFreedMemory();
    auto start = std::chrono::steady_clock::now();
    const pipeline::BakeOutcome outcome = pipeline::BakeAndWrite(atmosphere, job, dir);
    auto end = std::chrono::steady_clock::now();
    for (const BakeTiming& t : outcome.report.timings) {
      if (run == 0) m.phases.push_back(t.phase);
      m.seconds[t.phase].push_back(t.seconds);
    }
    m.seconds["total"].push_back(std::chrono::duration<double>(end - start).count());
  }
  return m;
}

// The scaling runs: the base configuration with one thing changed.
struct Variant {
  std::string name;
  std::function<void(BenchConfiguration&)> change;
};

std::vector<Variant> ScalingVariants() {
  std::vector<Variant> v = {
      {"transmittance mu x2", [](BenchConfiguration& c) { c.settings.transmittance_width *= 2; }},
      {"transmittance r x2", [](BenchConfiguration& c) { c.settings.transmittance_height *= 2; }},
      {"irradiance mu_s x2", [](BenchConfiguration& c) { c.settings.irradiance_width *= 2; }},
      {"irradiance r x2", [](BenchConfiguration& c) { c.settings.irradiance_height *= 2; }},
      {"scattering r x2", [](BenchConfiguration& c) { c.settings.scattering_r_size *= 2; }},
      {"scattering mu x2", [](BenchConfiguration& c) { c.settings.scattering_mu_size *= 2; }},
      {"scattering mu_s x2", [](BenchConfiguration& c) { c.settings.scattering_mu_s_size *= 2; }},
      {"scattering nu x2", [](BenchConfiguration& c) { c.settings.scattering_nu_size *= 2; }},
  };
  for (int orders = 1; orders <= 8; ++orders) {
    v.push_back({"orders " + std::to_string(orders), [orders](BenchConfiguration& c) { c.settings.orders = orders; }});
  }
  // Three wavelengths (the atmosphere's own, one per channel), and spectral
  // bakes of 15 and 45 in batches of three (bake/spectral.h), their higher
  // orders interpolated (the default) and computed at every wavelength.
  v.push_back({"wavelengths 3", [](BenchConfiguration& c) { c.wavelengths = 0; }});
  for (int wavelengths : {15, 45}) {
    v.push_back({"wavelengths " + std::to_string(wavelengths),
                 [wavelengths](BenchConfiguration& c) { c.wavelengths = wavelengths; }});
    v.push_back(
        {"wavelengths " + std::to_string(wavelengths) + ", exact higher orders", [wavelengths](BenchConfiguration& c) {
           c.wavelengths = wavelengths;
           c.spectral_higher_orders = SpectralHigherOrders::kExact;
         }});
  }
  // 1, 2 and, where the machine has more, all its cores.
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::vector<int> thread_counts = {1, 2};
  if (cores > 2) thread_counts.push_back(cores);
  for (int threads : thread_counts) {
    v.push_back({"threads " + std::to_string(threads), [threads](BenchConfiguration& c) { c.settings.threads = threads; }});
  }
  return v;
}

int WavelengthCount(const BenchConfiguration& c) { return c.wavelengths == 0 ? kWavelengthCount : c.wavelengths; }

void RunBench(const BenchOptions& o) {
  if (o.runs < 1 || o.runs > 1000) throw UsageError("--runs = " + std::to_string(o.runs) + " must be in [1, 1000]");
  CheckWavelengthsOption(o.wavelengths);
  const AtmosphereSource source = ReadAtmosphereSource(o.atmosphere);
  const Atmosphere atmosphere = ParseAtmosphere(source.text, source.name);
  const BenchConfiguration base_configuration{o.bake.Resolve(), o.wavelengths,
                                              ParseSpectralHigherOrders(o.spectral_higher_orders)};
  const BakeSettings& settings = base_configuration.settings;

  std::optional<ScratchDirectory> scratch;
  if (o.output_dir.empty()) scratch.emplace("skybake_bench_");
  const std::filesystem::path dir = scratch ? scratch->path() : std::filesystem::path(o.output_dir);
  EnsureWritableDirectory(dir);
  const std::string interrupt_note =
      "the benchmark did not finish" +
      (scratch ? std::string() : "; " + dir.string() + " holds the last set written to it, whole");

  ResetPeakResident();
  Measurement base = Measure(source, atmosphere, base_configuration, o.runs, dir, interrupt_note);
  const double peak_mib = PeakResidentMiB();
  const double base_total = Median(base.seconds["total"]);

  std::vector<std::pair<std::string, BenchConfiguration>> variants;
  std::vector<double> variant_totals, variant_peaks;
  if (o.scaling) {
    for (const Variant& v : ScalingVariants()) {
      BenchConfiguration changed = base_configuration;
      v.change(changed);
      changed.settings.Validate();
      variants.emplace_back(v.name, changed);
      ResetPeakResident();
      const Measurement measured = Measure(source, atmosphere, changed, o.runs, dir, interrupt_note);
      variant_totals.push_back(Median(measured.seconds.at("total")));
      variant_peaks.push_back(PeakResidentMiB());
    }
  }

  if (o.json) {
    nlohmann::json phases = nlohmann::json::array();
    for (const std::string& phase : base.phases) {
      phases.push_back({{"phase", phase}, {"median_seconds", Median(base.seconds[phase])}});
    }
    nlohmann::json scaling = nlohmann::json::array();
    for (size_t i = 0; i < variants.size(); ++i) {
      scaling.push_back({{"variant", variants[i].first},
                         {"settings", DescribeSettings(variants[i].second.settings, SettingsDetail::kOrdersAndThreads)},
                         {"wavelengths", WavelengthCount(variants[i].second)},
                         {"median_seconds", variant_totals[i]},
                         {"peak_resident_mib", variant_peaks[i]}});
    }
    nlohmann::json j = {{"atmosphere", atmosphere.name},
                        {"settings", DescribeSettings(settings, SettingsDetail::kOrdersAndThreads)},
                        {"wavelengths", WavelengthCount(base_configuration)},
                        {"runs", o.runs},
                        {"phases", phases},
                        {"median_total_seconds", base_total},
                        {"total_seconds", base.seconds["total"]},
                        {"peak_resident_mib", peak_mib},
                        {"scaling", scaling}};
    std::printf("%s\n", j.dump(2).c_str());
    return;
  }
  const std::string runs = o.runs == 1 ? "one run" : "median of " + std::to_string(o.runs) + " runs";
  std::printf("%s: %s, %d wavelengths, files written; %s\n\n", atmosphere.name.c_str(),
              DescribeSettings(settings, SettingsDetail::kOrdersAndThreads).c_str(),
              WavelengthCount(base_configuration), runs.c_str());
  std::printf("| phase | median (s) |\n|---|---:|\n");
  for (const std::string& phase : base.phases) {
    std::printf("| %s | %.3f |\n", phase.c_str(), Median(base.seconds[phase]));
  }
  std::printf("| **total** | **%.3f** |\n\npeak resident memory: %.0f MiB\n", base_total, peak_mib);
  if (o.scaling) {
    std::printf("\n| variant | median total (s) | x base | peak memory (MiB) | x base |\n|---|---:|---:|---:|---:|\n");
    for (size_t i = 0; i < variants.size(); ++i) {
      std::printf("| %s | %.3f | %.2f | %.0f | %.2f |\n", variants[i].first.c_str(), variant_totals[i],
                  variant_totals[i] / base_total, variant_peaks[i], variant_peaks[i] / peak_mib);
    }
  }
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Time each bake phase (median of several runs, files written) and report peak memory");
  cmd->add_option("atmosphere", o->atmosphere, "Atmosphere file (.toml) or preset name")->capture_default_str();
  cmd->add_option("--runs", o->runs, "Bakes per configuration; medians are reported")->capture_default_str();
  o->bake.AddTo(cmd);
  cmd->add_option("--wavelengths", o->wavelengths,
                  "Time a spectral bake of this many wavelengths, as bake --wavelengths; 0 = the atmosphere's own three")
      ->capture_default_str();
  cmd->add_option("--spectral-higher-orders", o->spectral_higher_orders,
                  "With --wavelengths: interpolated or exact, as bake --spectral-higher-orders")
      ->check(CLI::IsMember({"interpolated", "exact"}))
      ->capture_default_str();
  cmd->add_flag("--scaling", o->scaling,
                "Also time each table axis doubled, orders 1 to 8, 3, 15 and 45 wavelengths (the last two also with "
                "exact higher orders), and 1, 2 and all threads "
                "(total time and peak memory)");
  cmd->add_option("-o,--output", o->output_dir,
                  "Directory the bakes write to (default: a temporary one, removed afterwards)")
      ->check(OutputPath());
  cmd->add_flag("--json", o->json, "Print the figures as JSON instead of Markdown tables");
  cmd->callback([o] { RunBench(*o); });
}

}  // namespace skybake::cli
