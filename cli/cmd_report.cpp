// `skybake report`: error against bake time for a ladder of quality
// settings, and the run-time models side by side (docs/report.md, "The
// report"). Prints Markdown tables; writes report.csv, report.json and the
// error-against-time plot (SVG and PNG) into the output directory. The
// measurements and every form of the document are report/'s
// (report_run.h, report_document.h); this binds the options to them.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/config.h"
#include "cli/bake_settings_options.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "report/report_document.h"
#include "report/report_run.h"

namespace skybake::cli {

namespace {

struct ReportOptions {
  std::string atmosphere;
  std::string output_dir;
  std::string reference;  // empty: the committed reference, for earth only
  int wavelengths = kDefaultSpectralWavelengths;  // of the colour section's spectral bake; 0: none
  std::string spectral_reference;                 // empty: the committed one, for earth only
  BakeSettingsOptions bake;
  bool quick = false;
  std::vector<int> march_steps;  // empty: 4 8 16 32 (quick: 4 8)
  int passes = 0;                // timing passes; 0: 31 (quick: 3)
  bool json = false;
  bool quiet = false;
};

void RunReport(const ReportOptions& o) {
  CheckWavelengthsOption(o.wavelengths);
  report::ReportRequest request;
  request.source = ReadAtmosphereSource(o.atmosphere);
  const Atmosphere atmosphere = ParseAtmosphere(request.source.text, request.source.name);
  request.reference_file = o.reference;
  request.wavelengths = o.wavelengths;
  request.spectral_reference_file = o.spectral_reference;
  request.base = o.bake.Resolve();
  request.quick = o.quick;
  request.march_steps = o.march_steps;
  request.passes = o.passes;
  request.command_line = CommandLine();
  request.progress = [&](const std::string& line) {
    if (!o.quiet) std::fprintf(stderr, "report: %s\n", line.c_str());
  };
  const report::ReportDocument document = report::MeasureReport(atmosphere, request, o.output_dir);
  if (!report::WriteReportFiles(document, o.output_dir)) {
    std::fputs("report: no TrueType font found; the PNG plot has no text\n", stderr);
  }
  if (o.json) {
    std::printf("%s\n", report::ReportJson(document).dump(2).c_str());
  } else {
    std::printf("%s", report::ReportMarkdown(document).c_str());
  }
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report", "Error against bake time for a ladder of quality settings, and the run-time models side by side");
  cmd->add_option("atmosphere", o->atmosphere, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_option("-o,--output", o->output_dir, "Directory for report.csv, report.json and the plot")->required()
      ->check(OutputPath());
  cmd->add_option("--reference", o->reference,
                  "Reference values (skybake reference over a case set with a group column); "
                  "default: the committed one, for earth only");
  cmd->add_option("--wavelengths", o->wavelengths,
                  "Colour section: bake the base settings at this many wavelengths and measure them, and the base "
                  "bake read as sRGB, against the spectral reference (0: no colour section)")
      ->capture_default_str();
  cmd->add_option("--spectral-reference", o->spectral_reference,
                  "Spectral reference for the colour section (skybake reference --wavelengths N over a case set with "
                  "a group column); default: the committed one, for earth only");
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
