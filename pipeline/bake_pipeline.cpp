#include "pipeline/bake_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <utility>

#include "bake/spectral.h"
#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_tables.h"
#include "formats/manifest.h"
#include "formats/settings_record.h"
#include "pipeline/bake_inputs.h"
#include "shaders_runtime/snippet.h"

namespace skybake::pipeline {

namespace {

using nlohmann::json;

// printf onto the end of `out`.
__attribute__((format(printf, 2, 3))) void Append(std::string* out, const char* format, ...) {
  va_list args, copy;
  va_start(args, format);
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n > 0) {
    std::string text(static_cast<size_t>(n) + 1, '\0');
    std::vsnprintf(text.data(), text.size(), format, args);
    text.resize(static_cast<size_t>(n));
    *out += text;
  }
  va_end(args);
}

// The bytes the table files of a set take in `formats`, encoded in memory.
std::uint64_t TableFileBytes(const LutSet& luts, const WriteOptions& options) {
  std::uint64_t bytes = 0;
  for (const TableDescription& table : DescribeTables(luts)) {
    for (FileFormat format : options.formats) {
      bytes += EncodeTableImage(MakeTableFileImage(luts, table, format, options)).size();
    }
  }
  return bytes;
}

std::uint64_t TableFileBytes(const WriteReport& written) {
  std::uint64_t bytes = 0;
  for (const WrittenFile& f : written.files) bytes += f.table.empty() ? 0 : f.bytes;
  return bytes;
}

// The file formats by name, each once, in the order named.
std::vector<FileFormat> ParseFormats(const std::vector<std::string>& names) {
  std::vector<FileFormat> formats;
  for (const std::string& name : names) {
    std::optional<FileFormat> format = ParseFileFormat(name);
    if (!format) throw UsageError("--format: unknown format '" + name + "' (use exr, ktx2 or exr,ktx2)");
    if (std::find(formats.begin(), formats.end(), *format) == formats.end()) formats.push_back(*format);
  }
  if (formats.empty()) throw UsageError("--format: name at least one format (exr, ktx2)");
  return formats;
}

// The tables a scene stores as half floats (precision.*_half).
std::vector<std::string> SceneHalfTables(const Scene& scene) {
  const ScenePrecision& p = scene.precision;
  const std::pair<bool, const char*> tables[] = {{p.transmittance_half, "transmittance"},
                                                 {p.irradiance_half, "irradiance"},
                                                 {p.scattering_half, "scattering"},
                                                 {p.single_mie_scattering_half, "single_mie_scattering"}};
  std::vector<std::string> half;
  for (const auto& [is_half, table] : tables) {
    if (is_half) half.push_back(table);
  }
  return half;
}

std::string ErrorText(const report::ErrorStats& e) {
  char text[96];
  std::snprintf(text, sizeof text, "mean %.3f%% rms %.3f%% max %.3f%%", 100.0 * e.mean_relative,
                100.0 * e.rms_relative, 100.0 * e.max_relative);
  return text;
}

json ErrorJson(const report::ErrorStats& e) {
  return {{"mean_relative", e.mean_relative},
          {"rms_relative", e.rms_relative},
          {"max_relative", e.max_relative},
          {"values", e.count},
          {"rms_reference_noise", e.rms_noise}};
}

std::string SceneSummaryText(const SceneSummary& s) {
  std::string out;
  Append(&out, "  scene %s:\n", s.scene.name.c_str());
  for (const OmittedTable& t : s.plan.omitted) {
    Append(&out, "    left out %-22s %s\n", t.table.c_str(), t.reason.c_str());
  }
  if (!s.plan.aerial_perspective_functions) {
    Append(&out, "    left out %-22s no aerial_perspective\n", "GetSkyRadianceToPoint");
  }
  constexpr double kDegreesPerRadian = 180.0 / kPi;
  const double lowest_sun_deg = std::acos(s.plan.mu_s_min) * kDegreesPerRadian,
               full_lowest_sun_deg = std::acos(s.full_mu_s_min) * kDegreesPerRadian;
  // A scene that shows every sun (space views, a sun range to 180 deg)
  // keeps the atmosphere's lowest sun: then there is nothing "instead".
  char lowest[32], full_lowest[32];
  std::snprintf(lowest, sizeof lowest, "%.2f", lowest_sun_deg);
  std::snprintf(full_lowest, sizeof full_lowest, "%.2f", full_lowest_sun_deg);
  if (std::string(lowest) == full_lowest) {
    Append(&out, "    orders computed down to mu_s %.4f: the lowest sun %s deg, as in the full bake\n", s.plan.mu_s_min,
           lowest);
  } else {
    Append(&out, "    orders computed down to mu_s %.4f (full bake %.4f): lowest sun %s deg instead of %s deg\n",
           s.plan.mu_s_min, s.full_mu_s_min, lowest, full_lowest);
  }
  if (const std::optional<ScatteringRange>& range = s.range) {
    Append(&out,
           "    scattering tables restricted to altitudes %.4g-%.4g km and suns %.2f-%.2f deg (%d r texels "
           "instead of %d); orders on a %d x %d x %d (r, mu, mu_s) grid over the whole atmosphere\n",
           range->altitude_min_m / 1000.0, range->altitude_max_m / 1000.0,
           std::acos(range->mu_s_max) * kDegreesPerRadian, std::acos(range->mu_s_min) * kDegreesPerRadian,
           s.table_r_size, s.full_r_size, range->atmosphere_r_size, range->atmosphere_mu_size,
           range->atmosphere_mu_s_size);
  }
  if (!s.compared) return out;
  Append(&out, "    table bytes %llu vs %llu for the full bake in the same formats (%.1f%%)\n",
         static_cast<unsigned long long>(s.scene_table_bytes), static_cast<unsigned long long>(s.full_table_bytes),
         100.0 * double(s.scene_table_bytes) / double(s.full_table_bytes));
  Append(&out, "    bake time %.3f s vs %.3f s for the full bake (%.1f%%)\n", s.scene_bake_seconds,
         s.full_bake_seconds, 100.0 * s.scene_bake_seconds / s.full_bake_seconds);
  if (!s.accuracy) {
    Append(&out, "    accuracy: no reference cases for %s (pass --reference FILE)\n", s.scene.name.c_str());
    return out;
  }
  Append(&out, "    error on the %d reference cases of %s inside the scene (relative, every channel):\n",
         s.accuracy->cases, s.accuracy->reference.c_str());
  for (const report::SceneQuantityErrors& q : s.accuracy->quantities) {
    Append(&out, "      %-15s scene %s; full bake %s\n", q.quantity.c_str(), ErrorText(q.scene).c_str(),
           ErrorText(q.full).c_str());
  }
  return out;
}

json SceneSummaryJson(const SceneSummary& s) {
  json omitted = json::array();
  for (const OmittedTable& t : s.plan.omitted) omitted.push_back({{"table", t.table}, {"reason", t.reason}});
  json j = {{"name", s.scene.name},
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
      json quantities = json::object();
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

// The runtime's files in each of `languages`, its constants from `parameters`.
std::vector<ShaderFile> RuntimeShaderFiles(const std::vector<ShadingLanguage>& languages,
                                           const glsl::AtmosphereParameters& parameters, const Atmosphere& atmosphere,
                                           const SnippetParts& parts) {
  std::vector<ShaderFile> files;
  for (ShadingLanguage language : languages) {
    for (SnippetFile& f :
         RuntimeSnippetFiles(language, parameters, atmosphere.wavelengths_nm, atmosphere.name, parts)) {
      files.push_back(ShaderFile{f.file, std::move(f.text), f.description});
    }
  }
  return files;
}

// The names of the files the set will hold, known before the bake from a
// set without texels (SetFileNames): its tables from the settings and the
// scene, the runtime's files from their languages.
std::vector<std::string> PlannedFileNames(const Atmosphere& atmosphere, const BakeSettings& settings,
                                          const std::optional<SceneSummary>& scene,
                                          const std::vector<ShadingLanguage>& languages, WriteOptions options) {
  LutSet planned;
  planned.atmosphere = atmosphere;
  planned.settings = settings;
  planned.parameters = MakeAtmosphereParameters(atmosphere, settings);
  if (scene) planned.scene = scene->scene;
  options.shaders = RuntimeShaderFiles(languages, planned.parameters, atmosphere, {});
  return SetFileNames(planned, options);
}

// `out` for a set found up to date: the manifest's tables (without texels),
// orders and files, the settings as planned (the manifest's, with those it
// does not record), and the check as the one phase, timed from `start`.
void FillSkippedOutcome(Manifest set, std::chrono::steady_clock::time_point start, BakeOutcome* out) {
  out->skipped = true;
  out->luts = std::move(set.luts);
  out->atmosphere = out->luts.atmosphere.name;
  out->luts.settings = out->settings;
  out->report.orders_used = out->luts.orders_used;
  for (const ManifestFile& f : set.table_files) out->written.files.push_back({f.table, f.file, f.bytes});
  for (const ManifestFile& f : set.shader_files) out->written.files.push_back({"", f.file, f.bytes});
  std::error_code ec;
  out->written.files.push_back({"", kManifestFileName, std::filesystem::file_size(set.path, ec)});
  const BakeTiming check{"check the set is up to date",
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()};
  out->report.timings.push_back(check);
  out->report.total_seconds = check.seconds;
}

}  // namespace

BakeOutcome BakeAndWrite(const Atmosphere& full_atmosphere, const BakeJob& job, const std::filesystem::path& output_dir,
                         const BakeStepLine& on_step, const BakeProgress& on_phase) {
  const auto start = std::chrono::steady_clock::now();
  // The plan: a scene narrows the atmosphere's ranges and the settings, and
  // names the formats and the tables stored as half.
  BakeOutcome out;
  out.output_dir = output_dir;
  out.half = job.half;
  out.formats = job.formats;
  out.settings = job.settings;
  Atmosphere atmosphere = full_atmosphere;
  std::optional<SceneSummary>& scene = out.scene;
  if (!job.scene_file.empty()) {
    scene.emplace();
    scene->scene = LoadScene(job.scene_file);
    ValidateSceneForAtmosphere(scene->scene, atmosphere, InputName(job.scene_file));
    if (job.formats_given) {
      throw UsageError("--format: the scene names the formats (output.formats); give one or the other");
    }
    if (job.half) {
      throw UsageError("--half: the scene names each table's precision (precision, \"float\" where it names none); "
                       "give one or the other");
    }
    if (job.settings.pack_single_mie_in_alpha) {
      throw UsageError("--pack-mie: the scene decides the packing (effects.sharp_sun_halo); give one or the other");
    }
    out.formats = scene->scene.formats;
    scene->plan = PlanScene(scene->scene, atmosphere);
    scene->full_mu_s_min = atmosphere.mu_s_min;
  } else if (job.compare_full) {
    throw UsageError("--compare-full: needs --scene");
  }
  if (job.wavelengths != 0 && scene) throw UsageError("--wavelengths: a scene's bake has the atmosphere's three");
  std::optional<SpectralBatches> batches;
  if (job.wavelengths != 0)
    batches = MakeSpectralBatches(SpectralWavelengths(job.wavelengths), job.spectral_higher_orders);
  if (!job.reference_file.empty() && !job.compare_full) throw UsageError("--reference: needs --compare-full");
  // Read before baking, so that a bad file fails at once.
  std::optional<report::ReferenceSet> reference;
  if (job.compare_full) {
    reference = job.reference_file.empty() ? report::LoadCommittedCaseSets(atmosphere)
                                           : report::LoadReference(job.reference_file, atmosphere);
  }
  if (scene) {
    ApplyScenePlan(scene->plan, &atmosphere, &out.settings);
    scene->full_r_size = job.settings.scattering_r_size;
    scene->table_r_size = out.settings.scattering_r_size;
    scene->range = out.settings.scattering_range;
  }
  WriteOptions write_options;
  write_options.formats = ParseFormats(out.formats);
  if (job.ktx2_zstd_level > 0 && std::find(write_options.formats.begin(), write_options.formats.end(),
                                            FileFormat::kKtx2) == write_options.formats.end()) {
    throw UsageError(std::string("--ktx2-supercompression: only KTX2 files are supercompressed, and ") +
                     (scene ? "the scene's output.formats name" : "--format names") + " no ktx2; give one or the other");
  }
  write_options.half = job.half;
  write_options.ktx2_zstd_level = job.ktx2_zstd_level;
  if (scene) write_options.half_tables = SceneHalfTables(scene->scene);
  write_options.command_line = job.command_line;
  write_options.clean = job.clean;
  // Checked before baking, created only when the set is written, so a bake
  // that fails or is interrupted leaves no empty folder behind.
  CheckOutputDirectory(output_dir);

  // Incremental bakes (pipeline/bake_inputs.h): the manifest records the
  // inputs' hash, and a set up to date for it is left as it is. Otherwise
  // the files the folder holds besides are judged now, not after the bake.
  write_options.inputs_sha256 = BakeInputsSha256(full_atmosphere, job, batches ? &*batches : nullptr,
                                                 scene ? &scene->scene : nullptr, write_options);
  out.inputs_sha256 = write_options.inputs_sha256;
  if (job.skip_up_to_date && !job.compare_full) {
    if (std::optional<Manifest> set = ReadUpToDateSet(output_dir, out.inputs_sha256)) {
      if (on_step) on_step(atmosphere.name + ": " + output_dir.string() + " is up to date, not baked again");
      FillSkippedOutcome(std::move(*set), start, &out);
      return out;
    }
  }
  StaleSetFiles(output_dir, PlannedFileNames(atmosphere, out.settings, scene, job.runtime_languages, write_options),
                job.clean);

  // The bake (an interrupt leaves the folder as it was until the write's
  // commit: core/interrupt.h).
  out.atmosphere = atmosphere.name;
  auto step = [&](const std::string& line) {
    if (on_step) on_step(line);
  };
  step("baking " + atmosphere.name);
  out.luts = batches ? BakeSpectral(job.spectral_source, *batches, out.settings, &out.report, on_phase)
                    : Bake(atmosphere, out.settings, &out.report, on_phase);
  SnippetParts parts;
  parts.channels_are_xyz = out.luts.colour.has_value();
  if (scene) {
    out.luts.scene = scene->scene;
    parts.scattering = scene->plan.scattering;
    parts.irradiance = scene->plan.irradiance;
    parts.aerial_perspective = scene->plan.aerial_perspective_functions;
  }
  if (scene && job.compare_full) {
    // The full bake of the same atmosphere, sizes and formats, timed the same
    // way; its files are encoded in memory only, to count their bytes.
    step("baking " + atmosphere.name + " without the scene, for comparison");
    BakeReport full_report;
    const LutSet full = Bake(full_atmosphere, job.settings, &full_report);
    WriteOptions full_options = write_options;
    full_options.half_tables.clear();
    scene->compared = true;
    scene->full_bake_seconds = full_report.total_seconds;
    scene->scene_bake_seconds = out.report.total_seconds;
    scene->full_table_bytes = TableFileBytes(full, full_options);
    if (reference) scene->accuracy = report::MeasureSceneAccuracy(*reference, scene->scene, out.luts, full);
  }
  // The runtime goes beside the tables, its constants from this bake's parameters.
  write_options.shaders = RuntimeShaderFiles(job.runtime_languages, out.luts.parameters, atmosphere, parts);

  // The write, timed as one more phase.
  const auto write_start = std::chrono::steady_clock::now();
  out.written = WriteLutSet(out.luts, output_dir, write_options);
  const BakeTiming write{"write files",
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - write_start).count()};
  if (on_phase) on_phase(write);
  out.report.timings.push_back(write);
  out.report.total_seconds += write.seconds;
  if (scene) scene->scene_table_bytes = TableFileBytes(out.written);
  return out;
}

std::string BakeSummaryText(const BakeOutcome& outcome) {
  const BakeReport& report = outcome.report;
  const BakeSettings& settings = outcome.settings;
  std::string out;
  if (outcome.skipped) {
    Append(&out,
           "  %s records the same inputs (sha256 %.12s...) and the files it lists are there at their sizes "
           "(checked in %.3f s); --force bakes anyway\n",
           kManifestFileName, outcome.inputs_sha256.c_str(), report.total_seconds);
    return out;
  }
  Append(&out, "  %-36s %8.3f s\n", "total", report.total_seconds);
  Append(&out, "  orders used %d, ratio of the last two %.4g, extrapolated tail %.3g, ", report.orders_used,
         report.order_ratio, report.extrapolated_tail);
  if (report.remaining_error >= 0.0) {
    Append(&out, "estimated remaining error %.3g\n", report.remaining_error);
  } else {
    Append(&out, "remaining error unknown (fewer than two orders)\n");
  }
  if (settings.orders == 0 && !(report.remaining_error < settings.order_tolerance)) {
    Append(&out, "  warning: orders not converged to %g after %d orders\n", settings.order_tolerance,
           report.orders_used);
  }
  for (const auto& [table, error] : outcome.written.half_errors) {
    Append(&out,
           "  half: %-22s max relative error %.3g over %zu values >= %g; %zu smaller (%zu became 0), "
           "%zu overflowed\n",
           table.c_str(), error.max_relative_error, error.measured, error.floor, error.below_floor,
           error.flushed_to_zero, error.overflowed);
  }
  if (outcome.scene) out += SceneSummaryText(*outcome.scene);
  return out;
}

json BakeOutcomeJson(const BakeOutcome& outcome) {
  const BakeReport& report = outcome.report;
  json timings = json::array();
  for (const BakeTiming& t : report.timings) timings.push_back({{"phase", t.phase}, {"seconds", t.seconds}});
  json files = json::array();
  for (const WrittenFile& f : outcome.written.files) {
    files.push_back({{"file", f.file}, {"table", f.table.empty() ? json(nullptr) : json(f.table)}, {"bytes", f.bytes}});
  }
  json half_errors = json::object();
  for (const auto& [table, error] : outcome.written.half_errors) half_errors[table] = ToJson(error);
  // The settings' fields (orders, order_tolerance, tables, samples,
  // higher_order_divisor) sit at the top level beside the bake's.
  json j = json(SettingsJson(outcome.luts.settings, SettingsFields::kBakeReport));
  j["atmosphere"] = outcome.atmosphere;
  j["output_dir"] = outcome.output_dir.string();
  j["skipped"] = outcome.skipped;
  j["inputs_sha256"] = outcome.inputs_sha256;
  j["orders_used"] = report.orders_used;
  if (!outcome.skipped) {  // figures of the bake that the manifest does not record
    j["order_ratio"] = report.order_ratio;
    j["extrapolated_tail"] = report.extrapolated_tail;
    j["remaining_error"] = report.remaining_error >= 0.0 ? json(report.remaining_error) : json(nullptr);
  }
  j["pixel_type"] = outcome.half ? "half" : "float";
  j["formats"] = outcome.formats;
  j["files"] = files;
  if (!outcome.skipped) j["half_error"] = half_errors;
  j["timings"] = timings;
  j["total_seconds"] = report.total_seconds;
  if (outcome.scene) j["scene"] = SceneSummaryJson(*outcome.scene);
  return j;
}

}  // namespace skybake::pipeline
