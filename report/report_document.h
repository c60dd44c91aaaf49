// The document `skybake report` produces (docs/report.md, "The report"): one
// row per quality-ladder bake and per run-time model, each with its errors
// per case group, and the writers of every form it takes: the Markdown
// tables, report.json, report.csv and the error-against-bake-time plot.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "plot/plot.h"
#include "report/case_errors.h"
#include "report/colour_errors.h"

namespace skybake::report {

// One row of the report: a ladder bake or a run-time model.
struct ReportRow {
  std::string kind;  // "bake" or "model"
  std::string name, knob;
  bool is_base = false;
  bool pareto = false;
  double bake_seconds = -1.0;  // bakes only
  std::uint64_t bytes = 0;
  double ns_per_evaluation = -1.0;  // models only
  double texture_calls = 0.0, density_samples = 0.0, fitted_path_calls = 0.0;  // per evaluation, counted
  std::string note;
  BakeSettings settings;  // the bake's; for a model, the base bake's
  std::vector<GroupErrors> errors;
};

struct ReportDocument {
  std::string atmosphere;    // its name
  std::string reference;     // the reference's source name
  std::string command_line;  // recorded in report.json and under the plot
  std::vector<std::string> groups;       // measured case groups, in the reference's order
  std::vector<std::string> wavelengths;  // "680nm", ... (the per-channel column names)
  std::string plotted_group;             // "daylight", or the first group without one
  std::vector<ReportRow> rows;           // the ladder's bakes, then the models
  // The base settings baked spectrally, and the base bake read as sRGB,
  // against the spectral reference; absent without one (colour_errors.h).
  std::optional<ColourErrors> colour;
  std::string spectral_reference;  // its source name
};

// The error the plot and the Pareto front use: the luminance RMS of
// `group`, NaN where the row does not answer every case of it.
double PlottedError(const ReportRow& row, const std::string& group);

// Marks the bakes on the Pareto front of bake time against PlottedError of
// the plotted group (the models are not on it).
void MarkParetoFront(ReportDocument* document);

// The Markdown tables `skybake report` prints: the ladder, the base bake per
// wavelength and the run-time models.
std::string ReportMarkdown(const ReportDocument& document);
// report.json (schema in docs/report.md).
nlohmann::json ReportJson(const ReportDocument& document);
// report.csv: one line per row, group and quantity (each wavelength and luminance).
std::string ReportCsv(const ReportDocument& document);
// The ladder's bakes as error against bake time, the Pareto front and the base marked.
LinePlot ErrorAgainstTimePlot(const ReportDocument& document);

// Writes report.csv, report.json, error_vs_bake_time.svg and
// error_vs_bake_time.png into `dir`. The PNG is written (atomically) by
// OpenImageIO; the text files are staged so that they appear together or not
// at all, and an interrupt before then leaves none of them. False when no
// TrueType font was found, so the PNG has no text.
bool WriteReportFiles(const ReportDocument& document, const std::filesystem::path& dir);

}  // namespace skybake::report
