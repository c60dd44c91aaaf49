#include "report/report_run.h"

#include <algorithm>
#include <optional>

#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_tables.h"
#include "formats/query_csv.h"
#include "report/colour_errors.h"
#include "report/quality_ladder.h"
#include "report/run_time_models.h"

namespace skybake::report {

namespace {

// The run-time models, each measured on every case and timed over `passes`
// passes; the counts per evaluation come from `count` over every case. The
// table lookup reads `base_tables`, baked with `base`.
void AddModels(const Atmosphere& atmosphere, const ReferenceSet& reference, const BakeSettings& base,
               const LutSet& base_tables, const std::vector<int>& march_steps, int passes,
               ReportDocument* document) {
  std::vector<double> altitudes;
  for (const ReferenceCase& c : reference.cases) altitudes.push_back(c.query.altitude_m);
  auto add_model = [&](const std::string& name, const std::string& knob, const Model& model,
                       const std::function<void(const ReferenceCase&, ReportRow&)>& count) {
    ReportRow r;
    r.kind = "model";
    r.name = name;
    r.knob = knob;
    r.settings = base;
    r.errors = MeasureErrors(reference, model);
    r.ns_per_evaluation = MedianNanosecondsPerEvaluation(reference, model, passes);
    for (const ReferenceCase& c : reference.cases) count(c, r);
    double n = static_cast<double>(reference.cases.size());
    r.texture_calls /= n, r.density_samples /= n, r.fitted_path_calls /= n;
    document->rows.push_back(r);
  };
  Twin twin(MakeTwinTables(base_tables));
  add_model("table lookup (base bake)", "tables", [&](const ReferenceCase& c) { return EvaluateTwin(twin, c); },
            [&](const ReferenceCase& c, ReportRow& r) { r.texture_calls += CountTwinTextureCalls(base_tables, c); });
  HoffmanPreethamModel hoffman_preetham(atmosphere, altitudes);
  add_model("Hoffman & Preetham (fitted dome)", "analytic",
            [&](const ReferenceCase& c) { return hoffman_preetham.Evaluate(c); },
            [&](const ReferenceCase& c, ReportRow& r) {
              long calls = 0;
              hoffman_preetham.Evaluate(c, &calls);
              r.fitted_path_calls += calls;
            });
  if (!hoffman_preetham.available()) {
    document->rows.back().note = "not available: " + hoffman_preetham.unavailable_reason();
  }
  for (int steps : march_steps) {
    SingleScatteringRayMarch march(atmosphere, steps, steps);
    add_model("ray march, " + std::to_string(steps) + " x " + std::to_string(steps) + " steps", "ray march",
              [&](const ReferenceCase& c) { return EvaluateRayMarch(march, atmosphere.bottom_radius_m, c); },
              [&](const ReferenceCase& c, ReportRow& r) {
                long samples = 0;
                EvaluateRayMarch(march, atmosphere.bottom_radius_m, c, &samples);
                r.density_samples += samples;
              });
  }
}

}  // namespace

ReportDocument MeasureReport(const Atmosphere& atmosphere, const ReportRequest& request,
                             const std::filesystem::path& output_dir) {
  std::optional<ReferenceSet> loaded = LoadReference(request.reference_file, atmosphere);
  if (!loaded) {
    throw InputError("report: no committed reference for '" + atmosphere.name +
                     "' (only earth has one); compute one with skybake reference and pass --reference FILE");
  }
  const ReferenceSet& reference = *loaded;
  const LadderPlan plan = MakeLadder(request.base, request.quick);
  std::vector<int> march_steps = request.march_steps;
  if (march_steps.empty()) march_steps = request.quick ? std::vector<int>{4, 8} : std::vector<int>{4, 8, 16, 32};
  for (int steps : march_steps) {
    if (steps < 1 || steps > 4096) throw InputError("--march-steps: " + std::to_string(steps) + " is not in [1, 4096]");
  }
  const int passes = request.passes > 0 ? request.passes : request.quick ? 3 : 31;
  if (request.passes < 0 || passes > 10000) {
    throw InputError("--passes = " + std::to_string(request.passes) + " must be in [1, 10000]");
  }
  std::optional<ReferenceSet> spectral_reference;
  if (request.wavelengths != 0) {
    SpectralWavelengths(request.wavelengths);  // refuses a count that cannot be baked, before any bake
    spectral_reference = LoadSpectralReference(request.spectral_reference_file, atmosphere.name);
  } else if (!request.spectral_reference_file.empty()) {
    throw InputError("--spectral-reference: needs --wavelengths N (N >= 3) to bake against it");
  }
  EnsureWritableDirectory(output_dir);

  auto progress = [&](const std::string& line) {
    if (request.progress) request.progress(line);
  };
  LutSet base_tables;
  std::vector<LadderEntry> ladder;
  {
    const ScratchDirectory scratch("skybake_report_");
    ladder = RunLadder(atmosphere, plan, reference, scratch.path(), progress, &base_tables);
  }

  ReportDocument document;
  document.atmosphere = atmosphere.name;
  document.reference = reference.source_name;
  document.command_line = request.command_line;
  document.groups = MeasuredGroups(reference);
  const std::vector<std::string>& groups = document.groups;
  document.plotted_group =
      std::find(groups.begin(), groups.end(), "daylight") != groups.end() ? "daylight" : groups.front();
  for (int c = 0; c < kWavelengthCount; ++c) {
    document.wavelengths.push_back(WavelengthName(atmosphere.wavelengths_nm[c]));
  }
  for (const LadderEntry& e : ladder) {
    ReportRow r;
    r.kind = "bake";
    r.name = e.step.name;
    r.knob = e.step.knob;
    r.is_base = e.is_base;
    r.bake_seconds = e.bake_seconds;
    r.bytes = e.bytes;
    r.settings = e.step.settings;
    r.errors = e.errors;
    document.rows.push_back(r);
  }
  MarkParetoFront(&document);

  // The run-time models, on the base tables where they need tables.
  progress("run-time models: table lookup, Hoffman & Preetham (fitting the sky dome), ray march");
  AddModels(atmosphere, reference, plan.base, base_tables, march_steps, passes, &document);

  if (spectral_reference) {
    progress("colour: the base settings at " + std::to_string(request.wavelengths) + " wavelengths");
    BakeReport timing;
    const LutSet spectral = BakeSpectral(
        request.source, MakeSpectralBatches(SpectralWavelengths(request.wavelengths), kDefaultSpectralHigherOrders),
        plan.base, &timing);
    document.colour = MeasureColourErrors(*spectral_reference, spectral, base_tables);
    document.colour->spectral_bake_seconds = timing.total_seconds;
    document.spectral_reference = spectral_reference->source_name;
  }
  return document;
}

}  // namespace skybake::report
