// `skybake report`'s measurements as a ReportDocument (report_document.h):
// the quality ladder of bakes (quality_ladder.h) and the run-time models
// (run_time_models.h) against one reference.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "report/report_document.h"

namespace skybake::report {

struct ReportRequest {
  std::string reference_file;  // empty: the committed reference (earth only)
  BakeSettings base;           // the ladder's base bake
  bool quick = false;          // the quick ladder and fewer timing passes
  std::vector<int> march_steps;  // ray-march step counts; empty: 4 8 16 32 (quick: 4 8)
  int passes = 0;                // timing passes per model; 0: 31 (quick: 3)
  std::string command_line;      // recorded in the document
  std::function<void(const std::string&)> progress;  // a line per step; may be empty
};

// Checks the request (InputError without a reference for the atmosphere or
// for step counts or passes out of range, UsageError for auto orders) and
// that `output_dir` is a writable directory (creating it), then bakes the
// ladder in a scratch folder removed afterwards and measures every row.
ReportDocument MeasureReport(const Atmosphere& atmosphere, const ReportRequest& request,
                             const std::filesystem::path& output_dir);

}  // namespace skybake::report
