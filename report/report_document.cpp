#include "report/report_document.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <utility>

#include "core/file_io.h"
#include "formats/settings_record.h"
#include "report/error_stats.h"

namespace skybake::report {

namespace {

using nlohmann::json;

std::string Cell(const ErrorStats& s) {
  if (s.count == 0) return "n/a";
  return FormatRms(s) + " (" + FormatMax(s) + ")";
}

std::string GroupCell(const std::vector<GroupErrors>& errors, const std::string& group) {
  const GroupErrors& e = FindGroup(errors, group);
  return e.Answered() ? Cell(e.luminance) : "n/a";
}

std::string Megabytes(std::uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / 1e6);
  return text;
}

std::string Fixed(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

json ToJson(const ErrorStats& s) {
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"count", s.count},
          {"skipped", s.skipped},
          {"below_noise", s.below_noise},
          {"rms_relative", number(s.rms_relative)},
          {"max_relative", number(s.max_relative)},
          {"rms_noise", s.rms_noise},
          {"rms_below_noise", s.RmsBelowNoise()},
          {"max_below_noise", s.MaxBelowNoise()}};
}

}  // namespace

double PlottedError(const ReportRow& row, const std::string& group) {
  const GroupErrors& e = FindGroup(row.errors, group);
  return e.Answered() ? e.luminance.rms_relative : NAN;
}

void MarkParetoFront(ReportDocument* document) {
  std::vector<ReportRow*> bakes;
  std::vector<double> cost, error;
  for (ReportRow& r : document->rows) {
    if (r.kind != "bake") continue;
    bakes.push_back(&r);
    cost.push_back(r.bake_seconds), error.push_back(PlottedError(r, document->plotted_group));
  }
  std::vector<bool> front = ParetoFront(cost, error);
  for (size_t i = 0; i < bakes.size(); ++i) bakes[i]->pareto = front[i];
}

std::string ReportMarkdown(const ReportDocument& d) {
  const std::vector<std::string>& groups = d.groups;
  std::string out = "Errors are relative, in luminance (Rec. 709 weights), as RMS (max) over each group's cases; "
                    "\"below noise\": within " + Fixed(kNoiseStandardErrors, 0) +
                    " standard errors of the reference.\n\n";
  std::string header, rule;
  for (const std::string& g : groups) header += " " + g + " |", rule += "---|";

  out += "### Quality ladder (" + d.atmosphere + ")\n\n| configuration | bake (s) | written (MB) |" + header +
         " Pareto |\n|---|---:|---:|" + rule + ":---:|\n";
  for (const ReportRow& r : d.rows) {
    if (r.kind != "bake") continue;
    out += "| " + (r.is_base ? "**" + r.name + " (base)**" : r.name) + " | " + Fixed(r.bake_seconds, 1) + " | " +
           Megabytes(r.bytes) + " |";
    for (const std::string& g : groups) out += " " + GroupCell(r.errors, g) + " |";
    out += std::string(r.pareto ? " ● |" : " |") + "\n";
  }

  for (const ReportRow& r : d.rows) {
    if (!r.is_base) continue;
    out += "\n### The base bake per wavelength (RMS (max))\n\n| group |";
    for (const std::string& w : d.wavelengths) out += " " + w + " |";
    out += " luminance |\n|---|";
    for (size_t i = 0; i <= d.wavelengths.size(); ++i) out += "---|";
    out += "\n";
    for (const GroupErrors& e : r.errors) {
      out += "| " + e.group + " |";
      for (int c = 0; c < 3; ++c) out += " " + (e.Answered() ? Cell(e.channel[c]) : "n/a") + " |";
      out += " " + (e.Answered() ? Cell(e.luminance) : "n/a") + " |\n";
    }
  }

  out += "\n### Run-time models\n\n| model | ns / evaluation | texture fetches / eval. | loop iterations / eval. |" +
         header + "\n|---|---:|---:|---:|" + rule + "\n";
  for (const ReportRow& r : d.rows) {
    if (r.kind != "model") continue;
    std::string iterations = Fixed(r.density_samples, 1);
    if (r.fitted_path_calls > 0.0) iterations += " (+" + Fixed(r.fitted_path_calls, 1) + " fitted-path calls)";
    out += "| " + r.name + " | " + Fixed(r.ns_per_evaluation, 0) + " | " + Fixed(r.texture_calls, 1) + " | " +
           iterations + " |";
    for (const std::string& g : groups) out += " " + GroupCell(r.errors, g) + " |";
    out += "\n";
  }
  for (const ReportRow& r : d.rows) {
    if (!r.note.empty()) out += "\n" + r.name + ": " + r.note + "\n";
  }
  if (d.colour) {
    out += "\n### Colour (against " + d.spectral_reference +
           ")\n\nThe base settings baked at " + std::to_string(d.colour->wavelengths) +
           " wavelengths (tables in CIE XYZ), and the base bake's three wavelengths read as linear sRGB, against the "
           "spectral reference converted exactly: relative error of the luminance Y, and the chromaticity "
           "difference Δu′v′ (CIE 1976 UCS).\n\n" +
           ColourMarkdown(*d.colour);
  }
  return out;
}

json ReportJson(const ReportDocument& d) {
  json entries = json::array();
  for (const ReportRow& r : d.rows) {
    json errors = json::array();
    for (const GroupErrors& e : r.errors) {
      json per_wavelength;
      for (int c = 0; c < 3; ++c) per_wavelength[d.wavelengths[c]] = ToJson(e.channel[c]);
      errors.push_back({{"group", e.group},
                        {"answered", e.Answered()},
                        {"luminance", ToJson(e.luminance)},
                        {"per_wavelength", per_wavelength}});
    }
    json j = {{"kind", r.kind}, {"name", r.name}, {"knob", r.knob}, {"errors", errors}};
    if (r.kind == "bake") {
      j["is_base"] = r.is_base;
      j["pareto"] = r.pareto;
      j["bake_seconds"] = r.bake_seconds;
      j["bytes"] = r.bytes;
      j["settings"] = SettingsJson(r.settings, SettingsFields::kReportRow);
      j["half"] = r.knob == "storage";
    } else {
      j["ns_per_evaluation"] = r.ns_per_evaluation;
      j["texture_calls_per_evaluation"] = r.texture_calls;
      j["density_samples_per_evaluation"] = r.density_samples;
      j["fitted_path_calls_per_evaluation"] = r.fitted_path_calls;
      if (!r.note.empty()) j["note"] = r.note;
    }
    entries.push_back(j);
  }
  json document = {{"atmosphere", d.atmosphere},
                   {"reference", d.reference},
                   {"command_line", d.command_line},
                   {"noise_standard_errors", kNoiseStandardErrors},
                   {"luminance_weights", kLuminanceWeights},
                   {"rows", entries}};
  if (d.colour) {
    document["colour"] = ColourJson(*d.colour);
    document["colour"]["reference"] = d.spectral_reference;
  }
  return document;
}

std::string ReportCsv(const ReportDocument& d) {
  std::string out =
      "kind,name,knob,is_base,pareto,bake_seconds,bytes,ns_per_evaluation,texture_calls,density_samples,"
      "fitted_path_calls,group,quantity,answered,count,skipped,below_noise,rms_relative,max_relative,rms_noise,"
      "rms_below_noise,max_below_noise\n";
  char buffer[512];
  for (const ReportRow& r : d.rows) {
    for (const GroupErrors& e : r.errors) {
      for (int q = 0; q <= 3; ++q) {
        const ErrorStats& s = q < 3 ? e.channel[q] : e.luminance;
        std::snprintf(buffer, sizeof buffer,
                      "%s,%s,%s,%d,%d,%.6g,%llu,%.6g,%.6g,%.6g,%.6g,%s,%s,%d,%d,%d,%d,%.6g,%.6g,%.6g,%d,%d\n",
                      r.kind.c_str(), r.name.c_str(), r.knob.c_str(), r.is_base, r.pareto, r.bake_seconds,
                      static_cast<unsigned long long>(r.bytes), r.ns_per_evaluation, r.texture_calls,
                      r.density_samples, r.fitted_path_calls, e.group.c_str(),
                      q < 3 ? d.wavelengths[q].c_str() : "luminance", e.Answered(), s.count, s.skipped,
                      s.below_noise, s.rms_relative, s.max_relative, s.rms_noise, s.RmsBelowNoise(),
                      s.MaxBelowNoise());
        out += buffer;
      }
    }
  }
  return out;
}

LinePlot ErrorAgainstTimePlot(const ReportDocument& d) {
  const std::string& group = d.plotted_group;
  LinePlot plot;
  plot.title = d.atmosphere + ": " + group + " RMS luminance error against bake time";
  plot.caption = d.command_line;
  plot.x = {"bake time, files written (s)", true, {}, {}};
  plot.y = {group + " RMS relative luminance error", true, {}, {}};
  // One marker colour per knob, drawn last so that the larger markers of the
  // Pareto front and of the base show around them as rings.
  std::vector<PlotSeries> knobs;
  std::map<std::string, size_t> series_of_knob;
  std::vector<std::pair<double, double>> front;
  PlotSeries base;
  for (const ReportRow& r : d.rows) {
    if (r.kind != "bake") continue;
    double error = PlottedError(r, group);
    if (!series_of_knob.count(r.knob)) {
      series_of_knob[r.knob] = knobs.size();
      PlotSeries s;
      s.name = r.knob;
      s.color = static_cast<int>(knobs.size());
      s.width_px = 0.0;
      s.marker_px = 8.0;
      knobs.push_back(s);
    }
    PlotSeries& s = knobs[series_of_knob[r.knob]];
    s.x.push_back(r.bake_seconds);
    s.y.push_back(error);
    if (r.pareto) front.emplace_back(r.bake_seconds, error);
    if (r.is_base) base.name = "base (" + r.name + ")", base.x = {r.bake_seconds}, base.y = {error};
  }
  std::sort(front.begin(), front.end());
  PlotSeries pareto;
  pareto.name = "Pareto front";
  pareto.style = LineStyle::kDashed;
  pareto.color = static_cast<int>(knobs.size());
  pareto.marker_px = 14.0;
  pareto.width_px = 1.5;
  for (const auto& [x, y] : front) pareto.x.push_back(x), pareto.y.push_back(y);
  base.color = pareto.color + 1;
  base.width_px = 0.0;
  base.marker_px = 20.0;
  plot.series = {base, pareto};
  plot.series.insert(plot.series.end(), knobs.begin(), knobs.end());
  return plot;
}

bool WriteReportFiles(const ReportDocument& document, const std::filesystem::path& dir) {
  const LinePlot plot = ErrorAgainstTimePlot(document);
  StagedFiles files;
  const bool png_has_text = WritePlotPng(files, dir / "error_vs_bake_time.png", plot);
  files.Write(dir / "report.csv", ReportCsv(document));
  files.Write(dir / "report.json", ReportJson(document).dump(2) + "\n");
  files.Write(dir / "error_vs_bake_time.svg", RenderPlotSvg(plot));
  files.Commit();
  return png_has_text;
}

}  // namespace skybake::report
