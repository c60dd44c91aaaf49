// `skybake bake`: atmosphere → tables on disk.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/scene.h"
#include "cli/bake_settings_options.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/interrupt.h"
#include "formats/lut_files.h"
#include "formats/lut_tables.h"
#include "report/scene_accuracy.h"
#include "shaders_runtime/snippet.h"

namespace skybake::cli {

namespace {

struct BakeOptions {
  std::vector<std::string> atmospheres;
  std::string output_dir;  // with several atmospheres: a folder for one each, or a pattern with {name}
  bool clean = false;
  BakeSettingsOptions bake;
  std::vector<std::string> formats = {"exr", "ktx2"};
  bool half = false;
  bool json = false;
  bool quiet = false;
  std::string scene;
  bool compare_full = false;
  std::string reference;
  CLI::Option* format_option = nullptr;
};

// The bytes the table files of a set take in `formats`, encoded in memory.
std::uint64_t TableFileBytes(const LutSet& luts, const WriteOptions& options) {
  std::uint64_t bytes = 0;
  for (const TableDescription& table : DescribeTables(luts)) {
    const bool half = options.half || std::find(options.half_tables.begin(), options.half_tables.end(),
                                                table.name) != options.half_tables.end();
    for (FileFormat format : options.formats) {
      bytes += EncodeTableImage(MakeTableImage(luts, table, format, half ? PixelType::kHalf : PixelType::kFloat))
                   .size();
    }
  }
  return bytes;
}

std::uint64_t TableFileBytes(const WriteReport& written) {
  std::uint64_t bytes = 0;
  for (const WrittenFile& f : written.files) bytes += f.table.empty() ? 0 : f.bytes;
  return bytes;
}

// What a scene bake left out, and (with --compare-full) what it saved
// against the full bake of the same atmosphere, table sizes and formats and
// the error of both on the reference cases inside the scene.
struct SceneSummary {
  Scene scene;
  ScenePlan plan;
  double full_mu_s_min = 0.0;
  int full_r_size = 0, table_r_size = 0;
  std::optional<ScatteringRange> range;  // the bake's, where the plan restricts the tables
  bool compared = false;
  double full_bake_seconds = 0.0, scene_bake_seconds = 0.0;
  std::uint64_t full_table_bytes = 0, scene_table_bytes = 0;
  std::optional<report::SceneAccuracy> accuracy;  // with a reference for the atmosphere
};

std::string ErrorText(const report::ErrorStats& e) {
  char text[96];
  std::snprintf(text, sizeof text, "mean %.3f%% rms %.3f%% max %.3f%%", 100.0 * e.mean_relative,
                100.0 * e.rms_relative, 100.0 * e.max_relative);
  return text;
}

nlohmann::json ErrorJson(const report::ErrorStats& e) {
  return {{"mean_relative", e.mean_relative},
          {"rms_relative", e.rms_relative},
          {"max_relative", e.max_relative},
          {"values", e.count},
          {"rms_reference_noise", e.rms_noise}};
}

void PrintSceneSummary(const SceneSummary& s) {
  std::fprintf(stderr, "  scene %s:\n", s.scene.name.c_str());
  for (const OmittedTable& t : s.plan.omitted) {
    std::fprintf(stderr, "    left out %-22s %s\n", t.table.c_str(), t.reason.c_str());
  }
  if (!s.plan.aerial_perspective_functions) {
    std::fprintf(stderr, "    left out %-22s no aerial_perspective\n", "GetSkyRadianceToPoint");
  }
  constexpr double kDegreesPerRadian = 180.0 / kPi;
  std::fprintf(stderr, "    orders computed down to mu_s %.4f (full bake %.4f): lowest sun %.2f deg instead of %.2f deg\n",
               s.plan.mu_s_min, s.full_mu_s_min, std::acos(s.plan.mu_s_min) * kDegreesPerRadian,
               std::acos(s.full_mu_s_min) * kDegreesPerRadian);
  if (const std::optional<ScatteringRange>& range = s.range) {
    std::fprintf(stderr,
                 "    scattering tables restricted to altitudes %.4g-%.4g km and suns %.2f-%.2f deg (%d r texels "
                 "instead of %d); orders on a %d x %d x %d (r, mu, mu_s) grid over the whole atmosphere\n",
                 range->altitude_min_m / 1000.0, range->altitude_max_m / 1000.0,
                 std::acos(range->mu_s_max) * kDegreesPerRadian, std::acos(range->mu_s_min) * kDegreesPerRadian,
                 s.table_r_size, s.full_r_size, range->atmosphere_r_size, range->atmosphere_mu_size,
                 range->atmosphere_mu_s_size);
  }
  if (s.compared) {
    std::fprintf(stderr, "    table bytes %llu vs %llu for the full bake in the same formats (%.1f%%)\n",
                 static_cast<unsigned long long>(s.scene_table_bytes),
                 static_cast<unsigned long long>(s.full_table_bytes),
                 100.0 * double(s.scene_table_bytes) / double(s.full_table_bytes));
    std::fprintf(stderr, "    bake time %.3f s vs %.3f s for the full bake (%.1f%%)\n", s.scene_bake_seconds,
                 s.full_bake_seconds, 100.0 * s.scene_bake_seconds / s.full_bake_seconds);
    if (!s.accuracy) {
      std::fprintf(stderr, "    accuracy: no reference cases for %s (pass --reference FILE)\n",
                   s.scene.name.c_str());
    } else {
      std::fprintf(stderr, "    error on the %d reference cases of %s inside the scene (relative, every channel):\n",
                   s.accuracy->cases, s.accuracy->reference.c_str());
      for (const report::SceneQuantityErrors& q : s.accuracy->quantities) {
        std::fprintf(stderr, "      %-15s scene %s; full bake %s\n", q.quantity.c_str(), ErrorText(q.scene).c_str(),
                     ErrorText(q.full).c_str());
      }
    }
  }
}

nlohmann::json SceneSummaryJson(const SceneSummary& s) {
  nlohmann::json omitted = nlohmann::json::array();
  for (const OmittedTable& t : s.plan.omitted) omitted.push_back({{"table", t.table}, {"reason", t.reason}});
  nlohmann::json j = {{"name", s.scene.name},
                      {"omitted_tables", omitted},
                      {"aerial_perspective_functions", s.plan.aerial_perspective_functions},
                      {"orders_mu_s_min", s.plan.mu_s_min},
                      {"full_bake_mu_s_min", s.full_mu_s_min}};
  if (const std::optional<ScatteringRange>& range = s.range) {
    j["scattering_range"] = {{"altitude_m", {range->altitude_min_m, range->altitude_max_m}},
                             {"mu_s", {range->mu_s_min, range->mu_s_max}},
                             {"r_size", s.table_r_size},
                             {"full_r_size", s.full_r_size},
                             {"atmosphere_grid_r_mu_mu_s_size",
                              {range->atmosphere_r_size, range->atmosphere_mu_size, range->atmosphere_mu_s_size}}};
  }
  if (s.compared) {
    j["comparison"] = {{"scene_table_bytes", s.scene_table_bytes},
                       {"full_table_bytes", s.full_table_bytes},
                       {"scene_bake_seconds", s.scene_bake_seconds},
                       {"full_bake_seconds", s.full_bake_seconds}};
    if (s.accuracy) {
      nlohmann::json quantities = nlohmann::json::object();
      for (const report::SceneQuantityErrors& q : s.accuracy->quantities) {
        quantities[q.quantity] = {{"scene", ErrorJson(q.scene)}, {"full", ErrorJson(q.full)}};
      }
      j["comparison"]["accuracy"] = {{"reference", s.accuracy->reference},
                                     {"cases", s.accuracy->cases},
                                     {"groups", s.accuracy->groups},
                                     {"errors", quantities}};
    }
  }
  return j;
}

// Bakes one atmosphere into `output_dir`; the --json report of it.
nlohmann::json BakeOne(const BakeOptions& o, const std::string& atmosphere_arg, const std::string& output_dir) {
  Atmosphere atmosphere = LoadAtmosphere(atmosphere_arg);
  BakeSettings settings = o.bake.Resolve();
  std::optional<SceneSummary> scene;
  std::vector<std::string> formats = o.formats;
  if (!o.scene.empty()) {
    scene.emplace();
    scene->scene = LoadScene(o.scene);
    ValidateSceneForAtmosphere(scene->scene, atmosphere, std::filesystem::path(o.scene).filename().string());
    if (o.format_option != nullptr && o.format_option->count() > 0) {
      throw UsageError("--format: the scene names the formats (output.formats); give one or the other");
    }
    if (settings.pack_single_mie_in_alpha) {
      throw UsageError("--pack-mie: the scene decides the packing (effects.sharp_sun_halo); give one or the other");
    }
    formats = scene->scene.formats;
    scene->plan = PlanScene(scene->scene, atmosphere);
    scene->full_mu_s_min = atmosphere.mu_s_min;
  } else if (o.compare_full) {
    throw UsageError("--compare-full: needs --scene");
  }
  if (!o.reference.empty() && !o.compare_full) throw UsageError("--reference: needs --compare-full");
  // Read before baking, so that a bad file fails at once.
  std::optional<report::ReferenceSet> reference;
  if (o.compare_full) reference = report::LoadReference(o.reference, atmosphere);
  const Atmosphere full_atmosphere = atmosphere;
  const BakeSettings full_settings = settings;
  if (scene) {
    ApplyScenePlan(scene->plan, &atmosphere, &settings);
    scene->full_r_size = full_settings.scattering_r_size;
    scene->table_r_size = settings.scattering_r_size;
    scene->range = settings.scattering_range;
  }
  WriteOptions write_options;
  write_options.formats.clear();
  for (const std::string& name : formats) {
    std::optional<FileFormat> format = ParseFileFormat(name);
    if (!format) throw UsageError("--format: unknown format '" + name + "' (use exr, ktx2 or exr,ktx2)");
    if (std::find(write_options.formats.begin(), write_options.formats.end(), *format) == write_options.formats.end()) {
      write_options.formats.push_back(*format);
    }
  }
  if (write_options.formats.empty()) throw UsageError("--format: name at least one format (exr, ktx2)");
  write_options.half = o.half;
  if (scene) {
    const ScenePrecision& p = scene->scene.precision;
    const std::pair<bool, const char*> tables[] = {{p.transmittance_half, "transmittance"},
                                                   {p.irradiance_half, "irradiance"},
                                                   {p.scattering_half, "scattering"},
                                                   {p.single_mie_scattering_half, "single_mie_scattering"}};
    for (const auto& [half, table] : tables) {
      if (half) write_options.half_tables.push_back(table);
    }
  }
  write_options.command_line = CommandLine();
  write_options.clean = o.clean;
  // Checked before baking, created only when the set is written, so a bake
  // that fails or is interrupted leaves no empty folder behind.
  CheckOutputDirectory(output_dir);

  BakeReport report;
  // Each phase's end is a point where an interrupt leaves nothing behind.
  auto check_interrupt = [&](const BakeTiming&) { ThrowIfInterrupted("nothing was written to " + output_dir); };
  auto print_phase = [&](const BakeTiming& t) {
    if (!o.quiet) std::fprintf(stderr, "  %-36s %8.3f s\n", t.phase.c_str(), t.seconds);
    check_interrupt(t);
  };
  if (!o.quiet) std::fprintf(stderr, "baking %s\n", atmosphere.name.c_str());
  LutSet luts = Bake(atmosphere, settings, &report, print_phase);
  SnippetParts parts;
  if (scene) {
    luts.scene = scene->scene;
    parts.scattering = scene->plan.scattering;
    parts.irradiance = scene->plan.irradiance;
    parts.aerial_perspective = scene->plan.aerial_perspective_functions;
  }
  if (scene && o.compare_full) {
    // The full bake of the same atmosphere, sizes and formats, timed the same
    // way; its files are encoded in memory only, to count their bytes.
    if (!o.quiet) std::fprintf(stderr, "baking %s without the scene, for comparison\n", atmosphere.name.c_str());
    BakeReport full_report;
    const LutSet full = Bake(full_atmosphere, full_settings, &full_report, check_interrupt);
    WriteOptions full_options = write_options;
    full_options.half_tables.clear();
    scene->compared = true;
    scene->full_bake_seconds = full_report.total_seconds;
    scene->scene_bake_seconds = report.total_seconds;
    scene->full_table_bytes = TableFileBytes(full, full_options);
    if (reference) scene->accuracy = report::MeasureSceneAccuracy(*reference, scene->scene, luts, full);
  }
  // The GLSL runtime goes beside the tables, its constants from this bake's parameters.
  for (SnippetFile& f : RuntimeSnippetFiles(luts.parameters, atmosphere.wavelengths_nm, atmosphere.name, parts)) {
    write_options.shaders.push_back(ShaderFile{f.file, std::move(f.text), f.description});
  }

  auto write_start = std::chrono::steady_clock::now();
  WriteReport written = WriteLutSet(luts, output_dir, write_options);
  BakeTiming write{"write files", std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count()};
  print_phase(write);
  report.timings.push_back(write);
  report.total_seconds += write.seconds;
  if (scene) scene->scene_table_bytes = TableFileBytes(written);
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
    if (scene) PrintSceneSummary(*scene);
  }

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
      {"output_dir", output_dir},
      {"orders", s.orders == 0 ? nlohmann::json("auto") : nlohmann::json(s.orders)},
      {"orders_used", report.orders_used},
      {"order_tolerance", s.order_tolerance},
      {"order_ratio", report.order_ratio},
      {"extrapolated_tail", report.extrapolated_tail},
      {"remaining_error", report.remaining_error >= 0.0 ? nlohmann::json(report.remaining_error)
                                                        : nlohmann::json(nullptr)},
      {"pixel_type", o.half ? "half" : "float"},
      {"formats", formats},
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
      {"higher_order_divisor", s.higher_order_divisor},
      {"files", files},
      {"half_error", half_errors},
      {"timings", timings},
      {"total_seconds", report.total_seconds}};
  if (scene) j["scene"] = SceneSummaryJson(*scene);
  return j;
}

// Where each atmosphere's set goes: `output` with {name} replaced by the
// atmosphere's name, or, for several atmospheres and no {name}, output/name.
std::vector<std::string> OutputDirs(const BakeOptions& o) {
  constexpr std::string_view kName = "{name}";
  const bool pattern = o.output_dir.find(kName) != std::string::npos;
  std::vector<std::string> dirs;
  for (const std::string& atmosphere : o.atmospheres) {
    const std::string name = AtmosphereSourceName(atmosphere);
    std::string dir = o.output_dir;
    if (pattern) {
      for (std::size_t at; (at = dir.find(kName)) != std::string::npos;) dir.replace(at, kName.size(), name);
    } else if (o.atmospheres.size() > 1) {
      dir = (std::filesystem::path(o.output_dir) / name).string();
    }
    if (std::find(dirs.begin(), dirs.end(), dir) != dirs.end()) {
      throw UsageError("-o: two atmospheres would be baked into " + dir + " (name them apart, or use {name})");
    }
    dirs.push_back(dir);
  }
  return dirs;
}

void RunBake(const BakeOptions& o) {
  const std::string standard_input = kStandardStream;
  if (o.atmospheres.size() > 1 &&
      std::find(o.atmospheres.begin(), o.atmospheres.end(), standard_input) != o.atmospheres.end()) {
    throw UsageError("-: standard input can only be baked alone");
  }
  const std::vector<std::string> dirs = OutputDirs(o);
  InterruptScope interrupts;
  if (o.atmospheres.size() == 1) {
    nlohmann::json report = BakeOne(o, o.atmospheres[0], dirs[0]);
    if (o.json) std::printf("%s\n", report.dump(2).c_str());
    return;
  }
  // A batch: every atmosphere is baked (an interrupt stops the rest); one
  // summary, and the exit code of the first failure.
  nlohmann::json bakes = nlohmann::json::array();
  std::optional<Error> first_failure;
  int failures = 0;
  for (std::size_t i = 0; i < o.atmospheres.size(); ++i) {
    const std::string& atmosphere = o.atmospheres[i];
    try {
      ThrowIfInterrupted("not baked: " + std::to_string(o.atmospheres.size() - i) + " of " +
                         std::to_string(o.atmospheres.size()) + " atmospheres");
      nlohmann::json report = BakeOne(o, atmosphere, dirs[i]);
      std::fprintf(stderr, "bake %s -> %s: ok (%.3f s)\n", atmosphere.c_str(), dirs[i].c_str(),
                   report["total_seconds"].get<double>());
      report["input"] = atmosphere;
      bakes.push_back(report);
    } catch (const InterruptedError&) {
      throw;
    } catch (const Error& e) {
      std::fprintf(stderr, "bake %s -> %s: failed (exit %d): %s\n", atmosphere.c_str(), dirs[i].c_str(),
                   static_cast<int>(e.code()), e.what());
      bakes.push_back({{"input", atmosphere},
                       {"output_dir", dirs[i]},
                       {"error", {{"exit_code", static_cast<int>(e.code())}, {"message", e.what()}}}});
      ++failures;
      if (!first_failure) first_failure = e;
    }
  }
  std::fprintf(stderr, "baked %zu of %zu atmospheres\n", o.atmospheres.size() - failures, o.atmospheres.size());
  if (o.json) std::printf("%s\n", nlohmann::json({{"bakes", bakes}, {"failed", failures}}).dump(2).c_str());
  if (first_failure) {
    const Error summary(first_failure->code(),
                        std::to_string(failures) + " of " + std::to_string(o.atmospheres.size()) +
                            " bakes failed; the first: " + first_failure->what(),
                        first_failure->location());
    if (o.json) throw ReportedError(summary);  // each error is in the batch's JSON already
    throw summary;
  }
}

}  // namespace

void AddBakeCommand(CLI::App& app) {
  auto o = std::make_shared<BakeOptions>();
  CLI::App* cmd = app.add_subcommand("bake", "Bake transmittance, irradiance and scattering tables");
  cmd->add_option("atmosphere", o->atmospheres,
                  "Atmosphere files (.toml; - for standard input) or preset names (preset:NAME always names the "
                  "preset; a bare NAME is the preset where one exists, else a file); several are baked in turn")
      ->required();
  cmd->add_option("-o,--output", o->output_dir,
                  "Output directory (created if missing); {name} is replaced by the atmosphere's name; with "
                  "several atmospheres and no {name}, each goes to DIR/NAME")
      ->required();
  cmd->add_flag("--clean", o->clean,
                "Remove the files of an earlier set in the output directory that the new set does not list "
                "(without it, such files make the bake refuse; files no skybake set listed are never removed)");
  o->bake.AddTo(cmd);
  o->format_option = cmd->add_option("--format", o->formats,
                                     "File formats, comma-separated: exr, ktx2 (default exr,ktx2)")
                          ->delimiter(',')
                          ->capture_default_str();
  cmd->add_option("--scene", o->scene,
                  "Scene file (.toml, examples/scenes/README.md): bake and write only what the scene needs");
  cmd->add_flag("--compare-full", o->compare_full,
                "With --scene: also bake the full set (not written) and report the bytes and time saved and the "
                "error of both on the reference cases inside the scene");
  cmd->add_option("--reference", o->reference,
                  "With --compare-full: reference values (skybake reference over a case set with a group column); "
                  "default: the committed one for earth");
  cmd->add_flag("--half", o->half, "Store half floats instead of float32 (the error is reported)");
  cmd->add_flag("--json", o->json, "Print a machine-readable report (tables, sizes, orders, timings) on stdout");
  cmd->add_flag("-q,--quiet", o->quiet, "Do not print per-phase timings on stderr");
  cmd->callback([o] { RunBake(*o); });
}

}  // namespace skybake::cli
