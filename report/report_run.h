// `skybake report`'s measurements as a ReportDocument (report_document.h):
// the quality ladder of bakes (quality_ladder.h) and the run-time models
// (run_time_models.h) against one reference.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/config.h"
#include "bake/spectral.h"
#include "report/report_document.h"

namespace skybake::report {

struct ReportRequest {
  std::string reference_file;  // empty: the committed reference (earth only)
  // The colour section (colour_errors.h): the atmosphere's text, baked at
  // `wavelengths` (0: no colour section), against `spectral_reference_file`
  // (empty: the committed one, earth only; none: no colour section).
  AtmosphereSource source;
  int wavelengths = kDefaultSpectralWavelengths;
  std::string spectral_reference_file;
  BakeSettings base;           // the ladder's base bake
  bool quick = false;          // the quick ladder and fewer timing passes
  std::vector<int> march_steps;  // ray-march step counts; empty: 4 8 16 32 (quick: 4 8)
  int passes = 0;                // timing passes per model; 0: 31 (quick: 3)
  std::string command_line;      // recorded in the document
  std::function<void(const std::string&)> progress;  // a line per step; may be empty
};

// Checks the request (InputError without a reference for the atmosphere, for
// a spectral reference file given with no wavelengths to bake, or for step
// counts, passes or wavelengths out of range, UsageError for auto orders) and
// that `output_dir` is a writable directory (creating it), then bakes the
// ladder in a scratch folder removed afterwards and measures every row.
ReportDocument MeasureReport(const Atmosphere& atmosphere, const ReportRequest& request,
                             const std::filesystem::path& output_dir);

}  // namespace skybake::report
