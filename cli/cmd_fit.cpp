// `skybake fit`: fits the sky-dome optical-path surface (see fit/sky_dome_fit.h).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/config.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/version.h"
#include "fit/outputs.h"
#include "fit/query.h"
#include "fit/sky_dome_fit.h"

namespace skybake::cli {

namespace {

struct FitArguments {
  std::string atmosphere;
  std::string output_dir;
  std::vector<std::string> constituents;
  std::string query_file;
  bool json = false;
  std::string form = "auto";
  double altitude_min_m = 0.0;
  double altitude_max_m = 10000.0;
  double dome_altitude_m = 0.0;
  bool dome_altitude_given = false;  // default: the lowest observer altitude
  int dome_rings = 32;
  int dome_segments = 64;
};


void RunFit(const FitArguments& args) {
  if (args.output_dir.empty() && args.query_file.empty() && !args.json)
    throw UsageError("fit: nothing to do; give -o DIR, --query FILE or --json");
  if (args.json && !args.query_file.empty())
    throw UsageError("fit: --json and --query both print to stdout; use one");
  if (!args.query_file.empty() && args.constituents.size() != 1)
    throw UsageError("fit: --query needs exactly one --constituent NAME");
  const double low = args.altitude_min_m, high = args.altitude_max_m;
  if (!(low >= 0.0 && low <= high && std::isfinite(high))) {
    char message[160];
    std::snprintf(message, sizeof(message),
                  "fit: --altitude-min-m %g and --altitude-max-m %g must satisfy 0 <= min <= max < inf", low, high);
    throw UsageError(message);
  }

  fit::FitOptions options;
  options.altitude_min_m = args.altitude_min_m;
  options.altitude_max_m = args.altitude_max_m;
  if (args.form != "auto") {
    fit::FormKind kind;
    if (!fit::ParseFormKind(args.form, &kind))
      throw UsageError("fit: --form must be auto, chapman-chord or kasten (got '" + args.form + "')");
    options.forms = {kind};
  }

  // Read the queries first, so a typo fails before any slow part.
  std::vector<fit::Query> queries;
  std::string query_name = InputName(args.query_file);
  if (!args.query_file.empty()) queries = fit::ParseQueryCsv(ReadFileText(args.query_file), query_name);
  Atmosphere atmosphere = LoadAtmosphere(args.atmosphere);
  fit::CheckQueries(queries, atmosphere, query_name);
  double thickness = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  if (args.dome_altitude_given && !(args.dome_altitude_m >= 0.0 && args.dome_altitude_m < thickness)) {
    char message[160];
    std::snprintf(message, sizeof(message), "fit: --dome-altitude-m %g is outside the atmosphere [0, %g) m",
                  args.dome_altitude_m, thickness);
    throw InputError(message);
  }

  bool terminal = ::isatty(STDERR_FILENO);
  size_t total = args.constituents.empty() ? atmosphere.constituents.size() : args.constituents.size();
  size_t done = 0;
  fit::FitSet set = fit::FitAtmosphere(atmosphere, args.constituents, options, [&](const std::string& name) {
    if (terminal) std::fprintf(stderr, "\rfit: [%zu/%zu] %-30s", ++done, total, name.c_str());
  });
  if (terminal && total) std::fprintf(stderr, "\r%60s\r", "");

  fit::Provenance provenance{CommandLine(), SKYBAKE_VERSION};
  fit::DomeOptions dome;
  dome.altitude_m = args.dome_altitude_given ? args.dome_altitude_m : args.altitude_min_m;
  dome.rings = args.dome_rings;
  dome.segments = args.dome_segments;

  std::fputs(fit::ErrorTable(set).c_str(), stderr);
  fit::OutputSummary summary;
  if (!args.output_dir.empty()) {
    fit::OutputOptions out{args.output_dir, dome, provenance};
    summary = fit::WriteFitOutputs(atmosphere, set, out);
    if (!summary.plot_text) std::fputs("fit: no TrueType font found; the PNG plots have no text\n", stderr);
  } else if (args.json) {
    summary = fit::Summarize(atmosphere, set, dome, provenance, {});
  }
  if (!summary.mesh_note.empty()) std::fprintf(stderr, "fit: %s\n", summary.mesh_note.c_str());
  if (args.json) std::fputs(summary.report_json.c_str(), stdout);

  if (!args.query_file.empty()) {
    const Constituent* constituent = nullptr;
    for (const Constituent& c : atmosphere.constituents)
      if (c.name == args.constituents[0]) constituent = &c;
    const fit::ConstituentFit& fitted = set.constituents.at(0);
    if (!fitted.fitted) std::fprintf(stderr, "fit: %s not fitted (%s)\n", fitted.name.c_str(), fitted.skip_reason.c_str());
    std::fputs(fit::AnswerQueries(queries, atmosphere, *constituent, fitted).c_str(), stdout);
  }
}

}  // namespace

void AddFitCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "fit",
      "Fit a smooth surface to the relative optical path m(zenith, altitude) = slant column / vertical column "
      "of each constituent, and write GLSL + C++ evaluators, a sky-dome mesh, plots and fit.json");
  auto args = std::make_shared<FitArguments>();
  cmd->add_option("atmosphere", args->atmosphere, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_option("-o,--output", args->output_dir, "Output directory (created if needed)")
      ->check(OutputPath());
  cmd->add_option("--constituent", args->constituents, "Fit only this constituent (repeatable)");
  cmd->add_option("--query", args->query_file,
                  "CSV with columns zenith_deg,altitude_m: print exact, fitted and Iqbal m as CSV on stdout "
                  "(needs one --constituent)");
  cmd->add_flag("--json", args->json, "Print the fit report (fit.json) on stdout");
  cmd->add_option("--form", args->form, "auto (fit every form, keep the best), chapman-chord or kasten")
      ->capture_default_str();
  cmd->add_option("--altitude-min-m", args->altitude_min_m, "Lowest observer altitude, metres")->capture_default_str();
  cmd->add_option("--altitude-max-m", args->altitude_max_m, "Highest observer altitude, metres")->capture_default_str();
  CLI::Option* dome_altitude = cmd->add_option("--dome-altitude-m", args->dome_altitude_m,
                                               "Observer altitude of the sky-dome mesh, metres "
                                               "(default: --altitude-min-m)");
  cmd->add_option("--dome-rings", args->dome_rings, "Dome rings from zenith to horizon")
      ->capture_default_str()->check(CLI::Range(1, 4096));
  cmd->add_option("--dome-segments", args->dome_segments, "Dome azimuth segments")
      ->capture_default_str()->check(CLI::Range(3, 8192));
  cmd->callback([args, dome_altitude] {
    args->dome_altitude_given = dome_altitude->count() > 0;
    RunFit(*args);
  });
}

}  // namespace skybake::cli
