// `skybake bake`: atmosphere → tables on disk.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/errors.h"
#include "cli/bake_settings_options.h"
#include "cli/commands.h"
#include "cli/command_line.h"
#include "formats/file_io.h"
#include "formats/lut_files.h"
#include "shaders_runtime/snippet.h"

namespace skybake::cli {

namespace {

struct BakeOptions {
  std::string atmosphere;
  std::string output_dir;
  BakeSettingsOptions bake;
  std::vector<std::string> formats = {"exr", "ktx2"};
  bool half = false;
  bool json = false;
  bool quiet = false;
};

void RunBake(const BakeOptions& o) {
  Atmosphere atmosphere = LoadAtmosphere(o.atmosphere);
  const BakeSettings settings = o.bake.Resolve();
  WriteOptions write_options;
  write_options.formats.clear();
  for (const std::string& name : o.formats) {
    std::optional<FileFormat> format = ParseFileFormat(name);
    if (!format) throw UsageError("--format: unknown format '" + name + "' (use exr, ktx2 or exr,ktx2)");
    if (std::find(write_options.formats.begin(), write_options.formats.end(), *format) == write_options.formats.end()) {
      write_options.formats.push_back(*format);
    }
  }
  if (write_options.formats.empty()) throw UsageError("--format: name at least one format (exr, ktx2)");
  write_options.half = o.half;
  write_options.command_line = CommandLine();
  EnsureWritableDirectory(o.output_dir);

  BakeReport report;
  auto print_phase = [&](const BakeTiming& t) {
    if (!o.quiet) std::fprintf(stderr, "  %-36s %8.3f s\n", t.phase.c_str(), t.seconds);
  };
  if (!o.quiet) std::fprintf(stderr, "baking %s\n", atmosphere.name.c_str());
  LutSet luts = Bake(atmosphere, settings, &report, print_phase);
  // The GLSL runtime goes beside the tables, its constants from this bake's parameters.
  for (SnippetFile& f : RuntimeSnippetFiles(luts.parameters, atmosphere.wavelengths_nm, atmosphere.name)) {
    write_options.shaders.push_back(ShaderFile{f.file, std::move(f.text), f.description});
  }

  auto write_start = std::chrono::steady_clock::now();
  WriteReport written = WriteLutSet(luts, o.output_dir, write_options);
  BakeTiming write{"write files", std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count()};
  print_phase(write);
  report.timings.push_back(write);
  report.total_seconds += write.seconds;
  if (!o.quiet) {
    std::fprintf(stderr, "  %-36s %8.3f s\n", "total", report.total_seconds);
    std::fprintf(stderr, "  orders used %d, ratio of the last two %.4g, extrapolated tail %.3g, ", report.orders_used,
                 report.order_ratio, report.extrapolated_tail);
    if (report.remaining_error >= 0.0) {
      std::fprintf(stderr, "estimated remaining error %.3g\n", report.remaining_error);
    } else {
      std::fprintf(stderr, "remaining error unknown (fewer than two orders)\n");
    }
    if (settings.orders == 0 && !(report.remaining_error < settings.order_tolerance)) {
      std::fprintf(stderr, "  warning: orders not converged to %g after %d orders\n", settings.order_tolerance,
                   report.orders_used);
    }
    for (const auto& [table, error] : written.half_errors) {
      std::fprintf(stderr,
                   "  half: %-22s max relative error %.3g over %zu values >= %g; %zu smaller (%zu became 0), "
                   "%zu overflowed\n",
                   table.c_str(), error.max_relative_error, error.measured, error.floor, error.below_floor,
                   error.flushed_to_zero, error.overflowed);
    }
  }

  if (o.json) {
    nlohmann::json timings = nlohmann::json::array();
    for (const BakeTiming& t : report.timings) timings.push_back({{"phase", t.phase}, {"seconds", t.seconds}});
    nlohmann::json files = nlohmann::json::array();
    for (const WrittenFile& f : written.files) {
      files.push_back({{"file", f.file}, {"table", f.table.empty() ? nlohmann::json(nullptr) : nlohmann::json(f.table)},
                       {"bytes", f.bytes}});
    }
    nlohmann::json half_errors = nlohmann::json::object();
    for (const auto& [table, error] : written.half_errors) half_errors[table] = ToJson(error);
    const BakeSettings& s = luts.settings;
    nlohmann::json j = {
        {"atmosphere", atmosphere.name},
        {"output_dir", o.output_dir},
        {"orders", s.orders == 0 ? nlohmann::json("auto") : nlohmann::json(s.orders)},
        {"orders_used", report.orders_used},
        {"order_tolerance", s.order_tolerance},
        {"order_ratio", report.order_ratio},
        {"extrapolated_tail", report.extrapolated_tail},
        {"remaining_error", report.remaining_error >= 0.0 ? nlohmann::json(report.remaining_error)
                                                          : nlohmann::json(nullptr)},
        {"pixel_type", o.half ? "half" : "float"},
        {"formats", o.formats},
        {"tables",
         {{"transmittance", {s.transmittance_width, s.transmittance_height}},
          {"irradiance", {s.irradiance_width, s.irradiance_height}},
          {"scattering", {s.scattering_r_size, s.scattering_mu_size, s.scattering_mu_s_size, s.scattering_nu_size}},
          {"single_mie_scattering",
           s.pack_single_mie_in_alpha ? nlohmann::json(nullptr)
                                      : nlohmann::json({s.scattering_r_size, s.scattering_mu_size,
                                                        s.scattering_mu_s_size, s.scattering_nu_size})}}},
        {"samples",
         {{"transmittance", s.transmittance_samples}, {"ray", s.ray_samples}, {"sphere", s.sphere_samples}}},
        {"files", files},
        {"half_error", half_errors},
        {"timings", timings},
        {"total_seconds", report.total_seconds}};
    std::printf("%s\n", j.dump(2).c_str());
  }
}

}  // namespace

void AddBakeCommand(CLI::App& app) {
  auto o = std::make_shared<BakeOptions>();
  CLI::App* cmd = app.add_subcommand("bake", "Bake transmittance, irradiance and scattering tables");
  cmd->add_option("atmosphere", o->atmosphere, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_option("-o,--output", o->output_dir, "Output directory (created if missing)")->required();
  o->bake.AddTo(cmd);
  cmd->add_option("--format", o->formats, "File formats, comma-separated: exr, ktx2 (default exr,ktx2)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_flag("--half", o->half, "Store half floats instead of float32 (the error is reported)");
  cmd->add_flag("--json", o->json, "Print a machine-readable report (tables, sizes, orders, timings) on stdout");
  cmd->add_flag("-q,--quiet", o->quiet, "Do not print per-phase timings on stderr");
  cmd->callback([o] { RunBake(*o); });
}

}  // namespace skybake::cli
