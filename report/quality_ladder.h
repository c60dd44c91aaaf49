// The quality ladder of `skybake report`: bakes of one atmosphere with one
// accuracy knob changed at a time from a base configuration, each timed,
// written, and measured against the reference.
//
// The knobs: table resolution per axis group (transmittance and irradiance
// sizes; scattering r; scattering mu; scattering mu_s and nu) and the
// integration samples (ray samples; sphere samples) at x1/2 and x2, the
// orders 1..N from one bake (Bake's order snapshots), the preview bake
// (PreviewBakeSettings of the base: every size and sample at once), and half
// instead of float storage (the base tables rounded to half and back, as a
// half file stores them).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "report/case_errors.h"

namespace skybake::report {

struct LadderStep {
  std::string knob;  // "orders", "scattering r", "storage", ...
  std::string name;  // "orders 3", "scattering r x1/2", "half", ...
  BakeSettings settings;
  bool half = false;
};

struct LadderPlan {
  BakeSettings base;       // orders = the base's count
  int max_orders = 8;      // orders 1..max_orders (no tail) come from one bake; the base is baked on its own
  std::vector<LadderStep> variants;  // each a bake of its own, except half storage
};

// The full ladder (orders 1-8, every knob at x1/2 and x2, the preview, half), or the
// quick one for tests (orders 1-3, transmittance and irradiance sizes at
// x1/2 and x2, half). UsageError if the base's orders are auto.
LadderPlan MakeLadder(const BakeSettings& base, bool quick);

struct LadderEntry {
  LadderStep step;
  bool is_base = false;
  // Seconds of the bake's phases up to this configuration's last order plus
  // writing its files (EXR and KTX2, float or half, and the manifest);
  // orders and half storage share the base bake's write.
  double bake_seconds = 0.0;
  std::uint64_t bytes = 0;  // the files written
  std::vector<GroupErrors> errors;
};

// Runs the plan; the bakes write into `scratch_dir` (left for the caller to
// remove). `progress` gets a line per bake. `base_tables`, if given,
// receives the base configuration's tables.
std::vector<LadderEntry> RunLadder(const Atmosphere& atmosphere, const LadderPlan& plan,
                                   const ReferenceSet& reference, const std::filesystem::path& scratch_dir,
                                   const std::function<void(const std::string&)>& progress,
                                   LutSet* base_tables = nullptr);

// The tables as a half-float file stores them: every texel rounded to half.
LutSet RoundToHalf(LutSet tables);

}  // namespace skybake::report
