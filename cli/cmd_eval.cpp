// `skybake eval`: answers queries from baked tables through the CPU twin.
// The query format is documented in docs/eval.md.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bake/errors.h"
#include "cli/commands.h"
#include "formats/file_io.h"
#include "formats/lut_files.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/twin.h"

namespace skybake::cli {

namespace {

const std::vector<std::string> kRequiredColumns = {"altitude_m", "view_zenith_deg", "sun_zenith_deg",
                                                   "view_sun_azimuth_deg"};
const std::vector<std::string> kOptionalColumns = {"distance_m", "normal_zenith_deg"};

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) {
    size_t begin = field.find_first_not_of(" \t\r"), end = field.find_last_not_of(" \t\r");
    fields.push_back(begin == std::string::npos ? "" : field.substr(begin, end - begin + 1));
  }
  if (!line.empty() && line.back() == ',') fields.push_back("");
  return fields;
}

std::string WavelengthName(double nm) {
  char buffer[32];
  if (nm == std::round(nm)) {
    std::snprintf(buffer, sizeof(buffer), "%.0fnm", nm);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%gnm", nm);
  }
  return buffer;
}

struct EvalOptions {
  std::string lut_dir;
  std::string input;
  std::string output;
};

void RunEval(const EvalOptions& o) {
  std::string text = ReadFileText(o.input);
  LutSet luts = LoadLutSet(o.lut_dir);
  Twin twin(MakeTwinTables(luts));
  const std::string source = std::filesystem::path(o.input).filename().string();

  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") != std::string::npos) header = SplitCsvLine(line);
  }
  if (header.empty()) throw InputError(source + ": empty query file (expected a header line)");
  std::map<std::string, int> column;
  for (int i = 0; i < static_cast<int>(header.size()); ++i) {
    const std::string& name = header[i];
    bool known = std::find(kRequiredColumns.begin(), kRequiredColumns.end(), name) != kRequiredColumns.end() ||
                 std::find(kOptionalColumns.begin(), kOptionalColumns.end(), name) != kOptionalColumns.end();
    if (!known) throw InputError(source + ":" + std::to_string(line_number) + ": unknown column '" + name + "'");
    if (column.count(name)) throw InputError(source + ":" + std::to_string(line_number) + ": duplicate column '" + name + "'");
    column[name] = i;
  }
  for (const std::string& name : kRequiredColumns) {
    if (!column.count(name)) throw InputError(source + ": missing column '" + name + "'");
  }
  const bool has_distance = column.count("distance_m"), has_normal = column.count("normal_zenith_deg");

  std::string out;
  for (size_t i = 0; i < header.size(); ++i) out += (i ? "," : "") + header[i];
  std::vector<std::string> wavelengths;
  for (int c = 0; c < 3; ++c) wavelengths.push_back(WavelengthName(luts.atmosphere.wavelengths_nm[c]));
  for (const char* quantity : {"radiance_", "transmittance_"}) {
    for (const std::string& w : wavelengths) out += "," + std::string(quantity) + w;
  }
  if (has_normal) {
    for (const char* quantity : {"sun_irradiance_", "sky_irradiance_"}) {
      for (const std::string& w : wavelengths) out += "," + std::string(quantity) + w;
    }
  }
  out += "\n";

  while (std::getline(in, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> fields = SplitCsvLine(line);
    auto fail = [&](const std::string& problem) {
      throw InputError(source + ":" + std::to_string(line_number) + ": " + problem);
    };
    if (fields.size() != header.size()) {
      fail("expected " + std::to_string(header.size()) + " fields, got " + std::to_string(fields.size()));
    }
    auto number = [&](const std::string& name, double fallback, bool optional) {
      const std::string& field = fields[column.at(name)];
      if (field.empty()) {
        if (optional) return fallback;
        fail(name + " is empty");
      }
      char* end = nullptr;
      double value = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || *end != '\0') fail(name + " = '" + field + "' is not a number");
      if (!std::isfinite(value)) fail(name + " = " + field + " is not finite");
      return value;
    };
    auto angle = [&](const std::string& name, double low, double high, double fallback, bool optional) {
      double value = number(name, fallback, optional);
      if (value < low || value > high) {
        fail(name + " = " + fields[column.at(name)] + " is outside [" + std::to_string(int(low)) + ", " +
             std::to_string(int(high)) + "]");
      }
      return value;
    };
    Query q;
    q.altitude_m = number("altitude_m", 0.0, false);
    q.view_zenith_deg = angle("view_zenith_deg", 0.0, 180.0, 0.0, false);
    q.sun_zenith_deg = angle("sun_zenith_deg", 0.0, 180.0, 0.0, false);
    q.view_sun_azimuth_deg = number("view_sun_azimuth_deg", 0.0, false);
    if (has_distance) {
      q.distance_m = number("distance_m", 0.0, true);
      if (q.distance_m < 0.0) fail("distance_m = " + fields[column.at("distance_m")] + " is negative");
    }
    if (has_normal && !fields[column.at("normal_zenith_deg")].empty()) {
      q.has_normal = true;
      q.normal_zenith_deg = angle("normal_zenith_deg", 0.0, 180.0, 0.0, true);
    }
    // A camera below the ground is evaluated on the ground.
    q.altitude_m = std::max(q.altitude_m, 0.0);

    QueryGeometry g = MakeQueryGeometry(q, luts.parameters.bottom_radius);
    glsl::vec3 transmittance;
    glsl::vec3 radiance = q.distance_m > 0.0
        ? twin.SkyRadianceToPoint(g.camera, g.camera + g.view * q.distance_m, g.sun, &transmittance)
        : twin.SkyRadiance(g.camera, g.view, g.sun, &transmittance);
    char buffer[64];
    std::string row;
    for (size_t i = 0; i < fields.size(); ++i) row += (i ? "," : "") + fields[i];
    auto append = [&](const glsl::vec3& v) {
      for (int c = 0; c < 3; ++c) {
        std::snprintf(buffer, sizeof(buffer), ",%.9g", v[c]);
        row += buffer;
      }
    };
    append(radiance);
    append(transmittance);
    if (has_normal) {
      if (q.has_normal) {
        glsl::vec3 sky;
        glsl::vec3 sun = twin.SunAndSkyIrradiance(g.camera, g.normal, g.sun, &sky);
        append(sun);
        append(sky);
      } else {
        row += ",,,,,,";
      }
    }
    out += row + "\n";
  }

  if (o.output.empty() || o.output == "-") {
    std::fputs(out.c_str(), stdout);
  } else {
    WriteFileAtomically(o.output, out);
  }
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* cmd = app.add_subcommand(
      "eval", "Evaluate sky radiance, transmittance and irradiance queries (CSV) against baked tables");
  cmd->add_option("lut_dir", o->lut_dir, "Directory written by skybake bake")->required();
  cmd->add_option("--in", o->input, "Query CSV: altitude_m, view_zenith_deg, sun_zenith_deg, "
                                    "view_sun_azimuth_deg [, distance_m] [, normal_zenith_deg]")
      ->required();
  cmd->add_option("--out", o->output, "Result CSV (default: stdout)");
  cmd->callback([o] { RunEval(*o); });
}

}  // namespace skybake::cli
