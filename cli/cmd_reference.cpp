// `skybake reference`: answers the queries of `skybake eval` with the
// independent Monte Carlo reference (reference/path_tracer.h), each Monte
// Carlo figure with its standard error. Method: docs/reference.md.

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/config.h"
#include "bake/spectral.h"
#include "cli/bake_settings_options.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "reference/path_tracer.h"
#include "reference/query_csv.h"
#include "reference/spectral_reference.h"

namespace skybake::cli {

namespace {

struct ReferenceOptions {
  std::string atmosphere;
  std::string input;
  std::string output;
  std::string sun_transmittance = "quadrature";
  reference::Settings settings;
  int wavelengths = 0;
  bool quiet = false;
};

void RunReference(const ReferenceOptions& o) {
  reference::Settings settings = o.settings;
  if (o.sun_transmittance == "ratio-tracking") {
    settings.sun_transmittance = reference::SunTransmittanceMethod::kRatioTracking;
  } else if (o.sun_transmittance != "quadrature") {
    throw UsageError("--sun-transmittance must be 'quadrature' or 'ratio-tracking', not '" + o.sun_transmittance +
                     "'");
  }
  // Out-of-range values are option values, so usage errors.
  try {
    settings.Validate();
  } catch (const InputError& e) {
    throw UsageError(e.what());
  }
  CheckWavelengthsOption(o.wavelengths);
  QueryTable table = ParseQueryCsv(ReadFileText(o.input), InputName(o.input));
  const AtmosphereSource source = ReadAtmosphereSource(o.atmosphere);
  const Atmosphere atmosphere = ParseAtmosphere(source.text, source.name);

  std::vector<reference::Result> results;
  ChannelNames channels;
  if (o.wavelengths != 0) {
    const SpectralBatches batches =
        MakeSpectralBatches(SpectralWavelengths(o.wavelengths), SpectralHigherOrders::kExact);
    ProgressBar bar("reference", table.queries.size() * batches.size(), o.quiet);
    results = reference::EvaluateSpectral(source, batches, table.queries, settings, [&] { bar.Advance(); });
    bar.Finish();
    channels = XyzChannels();
  } else {
    reference::PathTracer tracer(atmosphere);
    ProgressBar bar("reference", table.queries.size(), o.quiet);
    for (size_t row = 0; row < table.queries.size(); ++row) {
      // The row number separates the random streams of the rows.
      results.push_back(tracer.Evaluate(table.queries[row], settings, row));
      bar.Advance();
    }
    bar.Finish();
    channels = WavelengthChannels(atmosphere.wavelengths_nm);
  }
  int64_t truncated = 0;
  for (const reference::Result& result : results) truncated += result.statistics.truncated;
  if (truncated > 0 && !o.quiet) {
    std::fprintf(stderr,
                 "skybake: warning: %lld paths reached %d scattering events and were stopped (optically very "
                 "thick medium); the radiance of those paths' later orders is missing\n",
                 static_cast<long long>(truncated), reference::kMaxEventsPerPath);
  }
  std::string out = reference::FormatResultCsv(table, results, channels);
  if (o.output.empty() || o.output == "-") {
    std::fputs(out.c_str(), stdout);
  } else {
    WriteFileAtomically(o.output, out);
  }
}

}  // namespace

void AddReferenceCommand(CLI::App& app) {
  auto o = std::make_shared<ReferenceOptions>();
  CLI::App* cmd = app.add_subcommand(
      "reference",
      "Answer eval's queries (CSV) with the independent Monte Carlo reference: radiance and sky irradiance "
      "with standard errors, transmittance and sun irradiance by quadrature");
  cmd->add_option("atmosphere", o->atmosphere, "Atmosphere file (.toml) or preset name")->required();
  cmd->add_option("--in", o->input,
                  "Query CSV: altitude_m, view_zenith_deg, sun_zenith_deg, view_sun_azimuth_deg "
                  "[, distance_m] [, normal_zenith_deg]")
      ->required();
  cmd->add_option("--out", o->output, "Result CSV (default: stdout)")
      ->check(OutputPath());
  cmd->add_option("--paths", o->settings.paths,
                  "Paths per wavelength for each Monte Carlo estimate (rounded up to blocks of 64); the standard "
                  "error falls as 1/sqrt(paths)")
      ->capture_default_str();
  cmd->add_option("--max-order", o->settings.max_order,
                  "Highest scattering order (scattering events + ground reflections; 1 = single scattering); "
                  "0 = all orders")
      ->capture_default_str();
  cmd->add_option("--wavelengths", o->wavelengths,
                  "Spectral: this many wavelengths (>= 3) evenly over 360-830 nm, three per run of the path "
                  "tracer, and the results in CIE XYZ (columns _X, _Y, _Z; Y in cd m^-2, lux for irradiance); "
                  "0 = the atmosphere's own three wavelengths")
      ->capture_default_str();
  cmd->add_option("--seed", o->settings.seed, "Random seed; the results depend on it, not on --threads")
      ->capture_default_str();
  cmd->add_option("--threads", o->settings.threads,
                  "Worker threads (0 = all cores; at most " + std::to_string(kMaxThreads) + ")")
      ->capture_default_str();
  cmd->add_option("--sun-transmittance", o->sun_transmittance,
                  "Sunlight attenuation at each path vertex: quadrature (exact, default) or ratio-tracking")
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No progress or warnings on stderr");
  cmd->callback([o] { RunReference(*o); });
}

}  // namespace skybake::cli
