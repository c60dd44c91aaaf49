// `skybake bake`: atmosphere → tables on disk. The pipeline is
// pipeline/bake_pipeline.h's; this binds the options, names each atmosphere's
// output folder and runs a batch.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
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
#include "formats/manifest.h"
#include "pipeline/bake_pipeline.h"
#include "shaders_runtime/snippet.h"

namespace skybake::cli {

namespace {

struct BakeOptions {
  std::vector<std::string> atmospheres;
  std::string output_dir;  // with several atmospheres: a folder for one each, or a pattern with {name}
  bool clean = false;
  bool force = false;    // bake even a set that is up to date
  std::string depfile;   // written after the bake: the set's manifest and the files it depends on
  BakeSettingsOptions bake;
  std::vector<std::string> formats = {"exr", "ktx2"};
  bool half = false;
  int wavelengths = 0;
  std::string spectral_higher_orders = ToString(kDefaultSpectralHigherOrders);
  std::string ktx2_supercompression = "none";
  std::vector<std::string> runtime = {"glsl", "hlsl", "msl", "wgsl"};
  bool json = false;
  bool quiet = false;
  std::string scene;
  bool compare_full = false;
  std::string reference;
  CLI::Option* format_option = nullptr;
  CLI::Option* spectral_higher_orders_option = nullptr;
};

// The value of --runtime: shading languages by name, or "none".
std::vector<ShadingLanguage> ParseRuntimeLanguages(const std::vector<std::string>& names) {
  if (names.size() == 1 && names[0] == "none") return {};
  std::vector<ShadingLanguage> languages;
  for (const std::string& name : names) {
    if (name == "none") throw UsageError("--runtime: none cannot be combined with languages");
    const std::optional<ShadingLanguage> language = ParseShadingLanguage(name);
    if (!language) throw UsageError("--runtime: '" + name + "' is not glsl, hlsl, msl, wgsl or none");
    if (std::find(languages.begin(), languages.end(), *language) == languages.end()) languages.push_back(*language);
  }
  return languages;
}

// Make syntax for a path in a depfile: spaces, '#' and '$' escaped.
std::string DepfilePath(const std::filesystem::path& path) {
  std::string escaped;
  for (char c : std::filesystem::absolute(path).lexically_normal().string()) {
    if (c == ' ' || c == '#') escaped += '\\';
    if (c == '$') escaped += '$';
    escaped += c;
  }
  return escaped;
}

// --depfile: one rule in Make syntax, as Ninja and Make read them (CMake's
// DEPFILE): the set's manifest, which a bake writes last and a skipped bake
// leaves as it is, depends on the files the bake read, the atmosphere file
// (a preset is inside the program) and the scene file. Absolute paths, so
// that the build's working directory does not matter.
void WriteDepfile(const std::string& depfile, const std::string& output_dir, const pipeline::BakeJob& job) {
  std::string rule = DepfilePath(std::filesystem::path(output_dir) / kManifestFileName) + ":";
  for (const std::string& input : {job.spectral_source.file, job.scene_file}) {
    if (!input.empty()) rule += " " + DepfilePath(input);
  }
  WriteFileAtomically(depfile, rule + "\n");
}

// Bakes one atmosphere into `output_dir` (pipeline/bake_pipeline.h), with the
// phases and the summary on stderr unless --quiet; the --json report of it.
nlohmann::json BakeOne(const BakeOptions& o, const std::string& atmosphere_arg, const std::string& output_dir) {
  pipeline::BakeJob job;
  job.spectral_source = ReadAtmosphereSource(atmosphere_arg);
  job.wavelengths = o.wavelengths;
  job.spectral_higher_orders = ParseSpectralHigherOrders(o.spectral_higher_orders);
  if (o.spectral_higher_orders_option->count() > 0 && o.wavelengths == 0) {
    throw UsageError("--spectral-higher-orders: needs --wavelengths N (a spectral bake)");
  }
  const Atmosphere atmosphere = ParseAtmosphere(job.spectral_source.text, job.spectral_source.name);
  job.settings = o.bake.Resolve();
  job.scene_file = o.scene;
  job.formats = o.formats;
  job.formats_given = o.format_option != nullptr && o.format_option->count() > 0;
  job.half = o.half;
  job.ktx2_zstd_level = ParseKtx2Supercompression(o.ktx2_supercompression);
  job.runtime_languages = ParseRuntimeLanguages(o.runtime);
  job.compare_full = o.compare_full;
  job.reference_file = o.reference;
  job.clean = o.clean;
  job.skip_up_to_date = !o.force;
  job.command_line = CommandLine();
  pipeline::BakeStepLine print_step;
  BakeProgress print_phase;
  if (!o.quiet) {
    print_step = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
    print_phase = [](const BakeTiming& t) { std::fprintf(stderr, "  %-36s %8.3f s\n", t.phase.c_str(), t.seconds); };
  }
  const pipeline::BakeOutcome outcome = pipeline::BakeAndWrite(atmosphere, job, output_dir, print_step, print_phase);
  if (!o.quiet) std::fputs(pipeline::BakeSummaryText(outcome).c_str(), stderr);
  if (!o.depfile.empty()) WriteDepfile(o.depfile, output_dir, job);
  return pipeline::BakeOutcomeJson(outcome);
}

// Where each atmosphere's set goes: `output` with {name} replaced by the
// atmosphere's name (AtmosphereSourceName: "stdin" for standard input), or,
// for several atmospheres and no {name}, output/name. Any other {...} is a
// placeholder skybake does not know: a usage error rather than a folder
// named after it.
std::vector<std::string> OutputDirs(const BakeOptions& o) {
  if (!o.depfile.empty() && o.atmospheres.size() > 1) {
    throw UsageError("--depfile: names the inputs of one set; bake one atmosphere per depfile");
  }
  constexpr std::string_view kName = "{name}";
  for (std::size_t open = o.output_dir.find('{'); open != std::string::npos; open = o.output_dir.find('{', open + 1)) {
    const std::size_t close = o.output_dir.find('}', open);
    if (close == std::string::npos) break;
    const std::string placeholder = o.output_dir.substr(open, close - open + 1);
    if (placeholder.find('{', 1) == std::string::npos && placeholder != kName) {
      throw UsageError("-o: unknown placeholder " + placeholder + " in " + o.output_dir +
                       " (the only one is {name}, the atmosphere's name)");
    }
  }
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

// The --json report of a batch: each atmosphere's report (or error) so far,
// the count of failures and, for a batch that stopped, the error that
// stopped it.
nlohmann::json BatchJson(const nlohmann::json& bakes, int failures, const Error* stopped_by = nullptr) {
  nlohmann::json batch = {{"bakes", bakes}, {"failed", failures}};
  if (stopped_by) {
    batch["error"] = {{"exit_code", static_cast<int>(stopped_by->code())}, {"message", stopped_by->what()}};
  }
  return batch;
}

void RunBake(const BakeOptions& o) {
  const std::string standard_input = kStandardStream;
  if (o.atmospheres.size() > 1 &&
      std::find(o.atmospheres.begin(), o.atmospheres.end(), standard_input) != o.atmospheres.end()) {
    throw UsageError("-: standard input can only be baked alone");
  }
  CheckWavelengthsOption(o.wavelengths);
  const std::vector<std::string> dirs = OutputDirs(o);
  if (o.atmospheres.size() == 1) {
    nlohmann::json report = BakeOne(o, o.atmospheres[0], dirs[0]);
    if (o.json) std::printf("%s\n", report.dump(2).c_str());
    return;
  }
  // A batch: every atmosphere is baked (an interrupt stops the rest, each
  // set finished before it complete); one summary, and the exit code of the
  // first failure.
  nlohmann::json bakes = nlohmann::json::array();
  std::optional<Error> first_failure;
  int failures = 0;
  for (std::size_t i = 0; i < o.atmospheres.size(); ++i) {
    const std::string& atmosphere = o.atmospheres[i];
    try {
      const std::string note = std::to_string(i) + " of " + std::to_string(o.atmospheres.size()) +
                               " atmospheres done before it (their sets complete); the folders of the rest were "
                               "left as they were";
      SetInterruptNote(note, [done = bakes, failures](const std::string& message) {
        const Error stopped(ExitCode::kInterrupted, message);
        return BatchJson(done, failures, &stopped).dump(2);
      });
      nlohmann::json report = BakeOne(o, atmosphere, dirs[i]);
      std::fprintf(stderr, "bake %s -> %s: ok (%.3f s)\n", atmosphere.c_str(), dirs[i].c_str(),
                   report["total_seconds"].get<double>());
      report["input"] = atmosphere;
      bakes.push_back(report);
    } catch (const InterruptedError& e) {
      if (!o.json) throw;
      std::printf("%s\n", BatchJson(bakes, failures, &e).dump(2).c_str());
      throw ReportedError(e);
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
  if (o.json) std::printf("%s\n", BatchJson(bakes, failures).dump(2).c_str());
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
                  "Output directory (created if missing); {name} is replaced by the atmosphere's name (the preset's, "
                  "the file's without .toml, stdin for standard input; no other {...} placeholder exists); with "
                  "several atmospheres and no {name}, each goes to DIR/NAME")
      ->required()
      ->check(OutputPath());
  cmd->add_flag("--clean", o->clean,
                "Remove the files of an earlier set in the output directory that the new set does not list "
                "(without it, such files make the bake refuse before baking); files no skybake manifest there "
                "listed (an engine's .meta files, a README) are left alone and never in the way");
  cmd->add_flag("--force", o->force,
                "Bake even when the output directory holds a set that is up to date: one whose manifest records "
                "the same inputs (atmosphere, settings, scene, formats, version) and whose files are there at "
                "their sizes, which is otherwise left as it is");
  cmd->add_option("--depfile", o->depfile,
                  "Also write FILE, a Make-syntax rule for build systems (Ninja, Make, CMake's DEPFILE): the set's "
                  "skybake.json depends on the atmosphere and scene files read; one atmosphere only")
      ->check(OutputPath());
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
                  "default: every case set committed for earth (its general, twilight and aerial-horizon cases)");
  cmd->add_option("--wavelengths", o->wavelengths,
                  "Spectral: bake this many wavelengths (>= 3; 15 is a good default) evenly over 360-830 nm, three "
                  "at a time, into tables in CIE 1931 XYZ, Y in cd m^-2 (docs/colour.md); 0 = the atmosphere's own "
                  "three wavelengths, one per channel")
      ->capture_default_str();
  o->spectral_higher_orders_option =
      cmd->add_option("--spectral-higher-orders", o->spectral_higher_orders,
                      "With --wavelengths: interpolated = the scattering orders >= 2 computed at the three "
                      "wavelengths nearest 460, 560 and 660 nm and interpolated at the others, about half the time; "
                      "exact = at every wavelength (docs/colour.md)")
          ->check(CLI::IsMember({"interpolated", "exact"}))
          ->capture_default_str();
  cmd->add_flag("--half", o->half,
                "Store half floats instead of float32 (the error is reported); not with --scene, whose precision "
                "names each table's");
  cmd->add_option("--ktx2-supercompression", o->ktx2_supercompression, kKtx2SupercompressionHelp)
      ->capture_default_str();
  cmd->add_option("--runtime", o->runtime,
                  "Shading languages of the runtime written beside the tables, comma-separated: glsl (OpenGL, "
                  "Vulkan), hlsl (Unity, Unreal), msl (Metal), wgsl (WebGPU); or none (default glsl,hlsl,msl,wgsl)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print a machine-readable report (tables, sizes, orders, timings) on stdout");
  cmd->add_flag("-q,--quiet", o->quiet, "Do not print per-phase timings on stderr");
  cmd->callback([o] { RunBake(*o); });
}

}  // namespace skybake::cli
