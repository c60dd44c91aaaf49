// `skybake report`: error against bake time for a ladder of quality
// settings, and the run-time models side by side (docs/report.md, "The
// report"). Prints Markdown tables; writes report.csv, report.json and the
// error-against-time plot (SVG and PNG) into the output directory.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "bake/config.h"
#include "cli/bake_settings_options.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/interrupt.h"
#include "plot/plot.h"
#include "formats/query_csv.h"
#include "report/case_errors.h"
#include "report/quality_ladder.h"
#include "report/run_time_models.h"

namespace skybake::cli {

namespace {

using nlohmann::json;
using report::GroupErrors;

struct ReportOptions {
  std::string atmosphere;
  std::string output_dir;
  std::string reference;  // empty: the committed reference, for earth only
  BakeSettingsOptions bake;
  bool quick = false;
  std::vector<int> march_steps;  // empty: 4 8 16 32 (quick: 4 8)
  int passes = 0;                // timing passes; 0: 31 (quick: 3)
  bool json = false;
  bool quiet = false;
};

// One row of the report: a ladder bake or a run-time model.
struct Row {
  std::string kind;  // "bake" or "model"
  std::string name, knob;
  bool is_base = false;
  bool pareto = false;
  double bake_seconds = -1.0;  // bakes only
  std::uint64_t bytes = 0;
  double ns_per_evaluation = -1.0;  // models only
  double texture_calls = 0.0, density_samples = 0.0, fitted_path_calls = 0.0;  // per evaluation, counted
  std::string note;
  std::vector<GroupErrors> errors;
};

std::string Cell(const report::ErrorStats& s) {
  if (s.count == 0) return "n/a";
  return report::FormatRms(s) + " (" + report::FormatMax(s) + ")";
}

std::string GroupCell(const std::vector<GroupErrors>& errors, const std::string& group) {
  const GroupErrors& e = report::FindGroup(errors, group);
  return e.Answered() ? Cell(e.luminance) : "n/a";
}

// The error the plot and the Pareto front use: the daylight luminance RMS
// (the first group if the reference has no daylight group).
double PlottedError(const Row& row, const std::string& group) {
  const GroupErrors& e = report::FindGroup(row.errors, group);
  return e.Answered() ? e.luminance.rms_relative : NAN;
}

std::string Megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / 1e6);
  return text;
}

std::string Fixed(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

std::string MarkdownTables(const std::string& atmosphere, const std::vector<Row>& rows,
                           const std::vector<std::string>& groups, const std::vector<std::string>& wavelengths) {
  std::string out = "Errors are relative, in luminance (Rec. 709 weights), as RMS (max) over each group's cases; "
                    "\"below noise\": within " + Fixed(report::kNoiseStandardErrors, 0) +
                    " standard errors of the reference.\n\n";
  std::string header, rule;
  for (const std::string& g : groups) header += " " + g + " |", rule += "---|";

  out += "### Quality ladder (" + atmosphere + ")\n\n| configuration | bake (s) | written (MB) |" + header +
         " Pareto |\n|---|---:|---:|" + rule + ":---:|\n";
  for (const Row& r : rows) {
    if (r.kind != "bake") continue;
    out += "| " + (r.is_base ? "**" + r.name + " (base)**" : r.name) + " | " + Fixed(r.bake_seconds, 1) + " | " +
           Megabytes(r.bytes) + " |";
    for (const std::string& g : groups) out += " " + GroupCell(r.errors, g) + " |";
    out += std::string(r.pareto ? " ● |" : " |") + "\n";
  }

  for (const Row& r : rows) {
    if (!r.is_base) continue;
    out += "\n### The base bake per wavelength (RMS (max))\n\n| group |";
    for (const std::string& w : wavelengths) out += " " + w + " |";
    out += " luminance |\n|---|";
    for (size_t i = 0; i <= wavelengths.size(); ++i) out += "---|";
    out += "\n";
    for (const GroupErrors& e : r.errors) {
      out += "| " + e.group + " |";
      for (int c = 0; c < 3; ++c) out += " " + (e.Answered() ? Cell(e.channel[c]) : "n/a") + " |";
      out += " " + (e.Answered() ? Cell(e.luminance) : "n/a") + " |\n";
    }
  }

  out += "\n### Run-time models\n\n| model | ns / evaluation | texture fetches / eval. | loop iterations / eval. |" +
         header + "\n|---|---:|---:|---:|" + rule + "\n";
  for (const Row& r : rows) {
    if (r.kind != "model") continue;
    std::string iterations = Fixed(r.density_samples, 1);
    if (r.fitted_path_calls > 0.0) iterations += " (+" + Fixed(r.fitted_path_calls, 1) + " fitted-path calls)";
    out += "| " + r.name + " | " + Fixed(r.ns_per_evaluation, 0) + " | " + Fixed(r.texture_calls, 1) + " | " +
           iterations + " |";
    for (const std::string& g : groups) out += " " + GroupCell(r.errors, g) + " |";
    out += "\n";
  }
  for (const Row& r : rows) {
    if (!r.note.empty()) out += "\n" + r.name + ": " + r.note + "\n";
  }
  return out;
}

json ToJson(const report::ErrorStats& s) {
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"count", s.count},
          {"skipped", s.skipped},
          {"below_noise", s.below_noise},
          {"rms_relative", number(s.rms_relative)},
          {"max_relative", number(s.max_relative)},
          {"rms_noise", s.rms_noise},
          {"rms_below_noise", s.RmsBelowNoise()},
          {"max_below_noise", s.MaxBelowNoise()}};
}

json SettingsJson(const BakeSettings& s) {
  return {{"transmittance_size", {s.transmittance_width, s.transmittance_height}},
          {"irradiance_size", {s.irradiance_width, s.irradiance_height}},
          {"scattering_size", {s.scattering_r_size, s.scattering_mu_size, s.scattering_mu_s_size, s.scattering_nu_size}},
          {"orders", s.orders},
          {"ray_samples", s.ray_samples},
          {"sphere_samples", s.sphere_samples},
          {"higher_order_divisor", s.higher_order_divisor}};
}

json ReportJson(const std::string& atmosphere, const std::string& reference, const std::vector<Row>& rows,
                const std::vector<BakeSettings>& settings, const std::vector<std::string>& wavelengths) {
  json entries = json::array();
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    json errors = json::array();
    for (const GroupErrors& e : r.errors) {
      json per_wavelength;
      for (int c = 0; c < 3; ++c) per_wavelength[wavelengths[c]] = ToJson(e.channel[c]);
      errors.push_back({{"group", e.group},
                        {"answered", e.Answered()},
                        {"luminance", ToJson(e.luminance)},
                        {"per_wavelength", per_wavelength}});
    }
    json j = {{"kind", r.kind}, {"name", r.name}, {"knob", r.knob}, {"errors", errors}};
    if (r.kind == "bake") {
      j["is_base"] = r.is_base;
      j["pareto"] = r.pareto;
      j["bake_seconds"] = r.bake_seconds;
      j["bytes"] = r.bytes;
      j["settings"] = SettingsJson(settings[i]);
      j["half"] = r.knob == "storage";
    } else {
      j["ns_per_evaluation"] = r.ns_per_evaluation;
      j["texture_calls_per_evaluation"] = r.texture_calls;
      j["density_samples_per_evaluation"] = r.density_samples;
      j["fitted_path_calls_per_evaluation"] = r.fitted_path_calls;
      if (!r.note.empty()) j["note"] = r.note;
    }
    entries.push_back(j);
  }
  return {{"atmosphere", atmosphere},
          {"reference", reference},
          {"command_line", CommandLine()},
          {"noise_standard_errors", report::kNoiseStandardErrors},
          {"luminance_weights", report::kLuminanceWeights},
          {"rows", entries}};
}

std::string ReportCsv(const std::vector<Row>& rows, const std::vector<std::string>& wavelengths) {
  std::string out =
      "kind,name,knob,is_base,pareto,bake_seconds,bytes,ns_per_evaluation,texture_calls,density_samples,"
      "fitted_path_calls,group,quantity,answered,count,skipped,below_noise,rms_relative,max_relative,rms_noise,"
      "rms_below_noise,max_below_noise\n";
  char buffer[512];
  for (const Row& r : rows) {
    for (const GroupErrors& e : r.errors) {
      for (int q = 0; q <= 3; ++q) {
        const report::ErrorStats& s = q < 3 ? e.channel[q] : e.luminance;
        std::snprintf(buffer, sizeof buffer,
                      "%s,%s,%s,%d,%d,%.6g,%llu,%.6g,%.6g,%.6g,%.6g,%s,%s,%d,%d,%d,%d,%.6g,%.6g,%.6g,%d,%d\n",
                      r.kind.c_str(), r.name.c_str(), r.knob.c_str(), r.is_base, r.pareto, r.bake_seconds,
                      static_cast<unsigned long long>(r.bytes), r.ns_per_evaluation, r.texture_calls,
                      r.density_samples, r.fitted_path_calls, e.group.c_str(),
                      q < 3 ? wavelengths[q].c_str() : "luminance", e.Answered(), s.count, s.skipped,
                      s.below_noise, s.rms_relative, s.max_relative, s.rms_noise, s.RmsBelowNoise(),
                      s.MaxBelowNoise());
        out += buffer;
      }
    }
  }
  return out;
}

LinePlot ErrorAgainstTimePlot(const std::string& atmosphere, const std::vector<Row>& rows, const std::string& group) {
  LinePlot plot;
  plot.title = atmosphere + ": " + group + " RMS luminance error against bake time";
  plot.caption = CommandLine();
  plot.x = {"bake time, files written (s)", true, {}, {}};
  plot.y = {group + " RMS relative luminance error", true, {}, {}};
  // One marker colour per knob, drawn last so that the larger markers of the
  // Pareto front and of the base show around them as rings.
  std::vector<PlotSeries> knobs;
  std::map<std::string, size_t> series_of_knob;
  std::vector<std::pair<double, double>> front;
  PlotSeries base;
  for (const Row& r : rows) {
    if (r.kind != "bake") continue;
    double error = PlottedError(r, group);
    if (!series_of_knob.count(r.knob)) {
      series_of_knob[r.knob] = knobs.size();
      PlotSeries s;
      s.name = r.knob;
      s.color = static_cast<int>(knobs.size());
      s.width_px = 0.0;
      s.marker_px = 8.0;
      knobs.push_back(s);
    }
    PlotSeries& s = knobs[series_of_knob[r.knob]];
    s.x.push_back(r.bake_seconds);
    s.y.push_back(error);
    if (r.pareto) front.emplace_back(r.bake_seconds, error);
    if (r.is_base) base.name = "base (" + r.name + ")", base.x = {r.bake_seconds}, base.y = {error};
  }
  std::sort(front.begin(), front.end());
  PlotSeries pareto;
  pareto.name = "Pareto front";
  pareto.style = LineStyle::kDashed;
  pareto.color = static_cast<int>(knobs.size());
  pareto.marker_px = 14.0;
  pareto.width_px = 1.5;
  for (const auto& [x, y] : front) pareto.x.push_back(x), pareto.y.push_back(y);
  base.color = pareto.color + 1;
  base.width_px = 0.0;
  base.marker_px = 20.0;
  plot.series = {base, pareto};
  plot.series.insert(plot.series.end(), knobs.begin(), knobs.end());
  return plot;
}

void RunReport(const ReportOptions& o) {
  namespace fs = std::filesystem;
  Atmosphere atmosphere = LoadAtmosphere(o.atmosphere);
  std::optional<report::ReferenceSet> loaded = report::LoadReference(o.reference, atmosphere);
  if (!loaded) {
    throw InputError("report: no committed reference for '" + atmosphere.name +
                     "' (only earth has one); compute one with skybake reference and pass --reference FILE");
  }
  const report::ReferenceSet& reference = *loaded;
  const report::LadderPlan plan = report::MakeLadder(o.bake.Resolve(), o.quick);
  std::vector<int> march_steps = o.march_steps;
  if (march_steps.empty()) march_steps = o.quick ? std::vector<int>{4, 8} : std::vector<int>{4, 8, 16, 32};
  for (int steps : march_steps) {
    if (steps < 1 || steps > 4096) throw InputError("--march-steps: " + std::to_string(steps) + " is not in [1, 4096]");
  }
  const int passes = o.passes > 0 ? o.passes : o.quick ? 3 : 31;
  if (o.passes < 0 || passes > 10000) throw InputError("--passes = " + std::to_string(o.passes) + " must be in [1, 10000]");
  EnsureWritableDirectory(o.output_dir);

  fs::path scratch = fs::temp_directory_path() / ("skybake_report_" + std::to_string(::getpid()));
  EnsureWritableDirectory(scratch);
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } cleanup{scratch};

  auto progress = [&](const std::string& line) {
    if (!o.quiet) std::fprintf(stderr, "report: %s\n", line.c_str());
  };
  LutSet base_tables;
  std::vector<report::LadderEntry> ladder =
      report::RunLadder(atmosphere, plan, reference, scratch, progress, &base_tables);

  std::vector<std::string> groups = report::MeasuredGroups(reference);
  const std::string plotted_group =
      std::find(groups.begin(), groups.end(), "daylight") != groups.end() ? "daylight" : groups.front();
  std::vector<std::string> wavelengths;
  for (int c = 0; c < kWavelengthCount; ++c) wavelengths.push_back(WavelengthName(atmosphere.wavelengths_nm[c]));

  std::vector<Row> rows;
  std::vector<BakeSettings> settings;
  for (const report::LadderEntry& e : ladder) {
    Row r;
    r.kind = "bake";
    r.name = e.step.name;
    r.knob = e.step.knob;
    r.is_base = e.is_base;
    r.bake_seconds = e.bake_seconds;
    r.bytes = e.bytes;
    r.errors = e.errors;
    rows.push_back(r);
    settings.push_back(e.step.settings);
  }
  std::vector<double> cost, error;
  for (const Row& r : rows) cost.push_back(r.bake_seconds), error.push_back(PlottedError(r, plotted_group));
  std::vector<bool> front = report::ParetoFront(cost, error);
  for (size_t i = 0; i < rows.size(); ++i) rows[i].pareto = front[i];

  // The run-time models, on the base tables where they need tables.
  progress("run-time models: table lookup, Hoffman & Preetham (fitting the sky dome), ray march");
  std::vector<double> altitudes;
  for (const report::ReferenceCase& c : reference.cases) altitudes.push_back(c.query.altitude_m);
  auto add_model = [&](const std::string& name, const std::string& knob, const report::Model& model,
                       const std::function<void(const report::ReferenceCase&, Row&)>& count) {
    Row r;
    r.kind = "model";
    r.name = name;
    r.knob = knob;
    r.errors = report::MeasureErrors(reference, model);
    r.ns_per_evaluation = report::MedianNanosecondsPerEvaluation(reference, model, passes);
    for (const report::ReferenceCase& c : reference.cases) count(c, r);
    double n = static_cast<double>(reference.cases.size());
    r.texture_calls /= n, r.density_samples /= n, r.fitted_path_calls /= n;
    rows.push_back(r);
    settings.push_back(plan.base);
  };
  Twin twin(MakeTwinTables(base_tables));
  add_model("table lookup (base bake)", "tables",
            [&](const report::ReferenceCase& c) { return report::EvaluateTwin(twin, c); },
            [&](const report::ReferenceCase& c, Row& r) {
              r.texture_calls += report::CountTwinTextureCalls(base_tables, c);
            });
  report::HoffmanPreethamModel hoffman_preetham(atmosphere, altitudes);
  add_model("Hoffman & Preetham (fitted dome)", "analytic",
            [&](const report::ReferenceCase& c) { return hoffman_preetham.Evaluate(c); },
            [&](const report::ReferenceCase& c, Row& r) {
              long calls = 0;
              hoffman_preetham.Evaluate(c, &calls);
              r.fitted_path_calls += calls;
            });
  if (!hoffman_preetham.available()) rows.back().note = "not available: " + hoffman_preetham.unavailable_reason();
  for (int steps : march_steps) {
    report::SingleScatteringRayMarch march(atmosphere, steps, steps);
    add_model("ray march, " + std::to_string(steps) + " x " + std::to_string(steps) + " steps", "ray march",
              [&](const report::ReferenceCase& c) {
                return report::EvaluateRayMarch(march, atmosphere.bottom_radius_m, c);
              },
              [&](const report::ReferenceCase& c, Row& r) {
                long samples = 0;
                report::EvaluateRayMarch(march, atmosphere.bottom_radius_m, c, &samples);
                r.density_samples += samples;
              });
  }

  // The PNG is written (atomically) by OpenImageIO; the text files are
  // staged so that the CSV, JSON and SVG appear together or not at all.
  const fs::path dir = o.output_dir;
  const json j = ReportJson(atmosphere.name, reference.source_name, rows, settings, wavelengths);
  LinePlot plot = ErrorAgainstTimePlot(atmosphere.name, rows, plotted_group);
  if (!WritePlotPng(dir / "error_vs_bake_time.png", plot)) {
    std::fputs("report: no TrueType font found; the PNG plot has no text\n", stderr);
  }
  {
    InterruptScope interrupts;
    StagedFiles files;
    files.Write(dir / "report.csv", ReportCsv(rows, wavelengths));
    files.Write(dir / "report.json", j.dump(2) + "\n");
    files.Write(dir / "error_vs_bake_time.svg", RenderPlotSvg(plot));
    ThrowIfInterrupted("the report in " + dir.string() + " was not written");
    files.Commit();
  }
  if (o.json) {
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("%s", MarkdownTables(atmosphere.name, rows, groups, wavelengths).c_str());
  }
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Error against bake time for a ladder of quality settings, and the run-time models side by side");
  cmd->add_option("atmosphere", o->atmosphere, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_option("-o,--output", o->output_dir, "Directory for report.csv, report.json and the plot")->required();
  cmd->add_option("--reference", o->reference,
                  "Reference values (skybake reference over a case set with a group column); "
                  "default: the committed one, for earth only");
  o->bake.AddTo(cmd);
  cmd->add_flag("--quick", o->quick,
                "A small ladder (orders 1-3, transmittance and irradiance sizes, half) and fewer timing passes");
  cmd->add_option("--march-steps", o->march_steps, "Ray-march step counts, view and light (default 4 8 16 32)");
  cmd->add_option("--passes", o->passes, "Timing passes over the cases per run-time model (default 31)");
  cmd->add_flag("--json", o->json, "Print report.json instead of the Markdown tables");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress lines on stderr");
  cmd->callback([o] { RunReport(*o); });
}

}  // namespace skybake::cli
