// The bake pipeline, from an atmosphere to a table set on disk: the scene's
// plan (bake/scene.h) applied to the atmosphere and settings, the bake, the
// storage (float, half, a scene's half tables), with --compare-full the
// full bake it is measured against, the GLSL runtime beside the tables, and
// the staged write (formats/lut_files.h), skipped where the folder holds
// the set of the same inputs (pipeline/bake_inputs.h). `skybake bake` and
// `skybake bench` bake through it; BakeSummaryText and BakeOutcomeJson are
// the forms `skybake bake` reports a bake in.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/scene.h"
#include "bake/spectral.h"
#include "formats/lut_files.h"
#include "report/scene_accuracy.h"
#include "shaders_runtime/snippet.h"

namespace skybake::pipeline {

struct BakeJob {
  BakeSettings settings;
  std::string scene_file;                              // empty: the whole atmosphere
  std::vector<std::string> formats = {"exr", "ktx2"};  // file formats by name; a scene names its own
  bool formats_given = false;  // the formats were asked for, which a scene refuses
  bool half = false;           // every table as half floats
  int ktx2_zstd_level = 0;     // WriteOptions::ktx2_zstd_level
  bool compare_full = false;   // with a scene: also bake the full set (not written) and compare
  std::string reference_file;  // with compare_full; empty: the committed case sets (earth only)
  // The runtime's languages written beside the tables (shaders_runtime/snippet.h); empty: none.
  std::vector<ShadingLanguage> runtime_languages{std::begin(kShadingLanguages), std::end(kShadingLanguages)};
  bool clean = false;          // WriteOptions::clean
  // Leave a set in the output directory that is up to date for these inputs
  // as it is (pipeline/bake_inputs.h) instead of baking it again; never with
  // compare_full, which measures the bake.
  bool skip_up_to_date = false;
  // A spectral bake (bake/spectral.h) of this many wavelengths, reading
  // `spectral_source` (the atmosphere's text) at each batch; 0: the
  // atmosphere's own three wavelengths (SpectralWavelengths refuses 1, 2 and
  // negative counts).
  int wavelengths = 0;
  SpectralHigherOrders spectral_higher_orders = kDefaultSpectralHigherOrders;
  AtmosphereSource spectral_source;
  std::string command_line;    // recorded in the manifest
};

// What a scene bake left out, and (with compare_full) what it saved against
// the full bake of the same atmosphere, table sizes and formats and the
// error of both on the reference cases inside the scene.
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

struct BakeOutcome {
  std::string atmosphere;  // its name
  std::filesystem::path output_dir;
  std::string inputs_sha256;  // the hash of the inputs (pipeline/bake_inputs.h), as the manifest records it
  // The set in output_dir was up to date and left as it was: nothing was
  // baked or written; luts (without texels) and written are the manifest's,
  // and the report's one phase is the check.
  bool skipped = false;
  std::vector<std::string> formats;  // as named (the job's or the scene's)
  bool half = false;
  BakeSettings settings;  // as baked: the scene's plan applied
  LutSet luts;
  BakeReport report;  // the phases, "write files" last, and the total
  WriteReport written;
  std::optional<SceneSummary> scene;
};

// Called with a line before each bake ("baking NAME", and for the
// comparison "baking NAME without the scene, for comparison").
using BakeStepLine = std::function<void(const std::string&)>;

// Runs the pipeline into `output_dir`. UsageError for options that do not go
// together (formats, half or --pack-mie with a scene, compare_full without
// one, a reference without compare_full, a KTX2 supercompression without
// KTX2 files, an unknown or no format); the scene, the
// reference and the output directory, with the files it holds
// (StaleSetFiles in formats/lut_files.h), are checked before anything is
// baked. With job.skip_up_to_date a set there that is up to date is left as
// it is (BakeOutcome::skipped).
// `on_phase` sees each phase of the written set's bake and its writing. The
// set is written as one commit (core/interrupt.h: an interrupt before it
// leaves `output_dir` as it was). Either callback may be empty.
BakeOutcome BakeAndWrite(const Atmosphere& atmosphere, const BakeJob& job, const std::filesystem::path& output_dir,
                         const BakeStepLine& on_step = nullptr, const BakeProgress& on_phase = nullptr);

// The lines `skybake bake` prints after a bake: the total, the orders and
// their convergence, the error of half storage and the scene's summary.
std::string BakeSummaryText(const BakeOutcome& outcome);

// The report of `skybake bake --json` (tables, sizes, orders, files, timings, scene).
nlohmann::json BakeOutcomeJson(const BakeOutcome& outcome);

}  // namespace skybake::pipeline
