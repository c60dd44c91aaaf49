#include "formats/query_csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>

#include "core/errors.h"

namespace skybake {

namespace {

// Altitudes and distances beyond 1e12 m (6.7 au) are rejected: there the
// runtime's ray-sphere arithmetic has lost its digits, and past ~1e154 m its
// squares overflow and answer NaN.
constexpr double kMaxLengthM = 1e12;
const std::vector<std::string> kRequiredColumns = {"altitude_m", "view_zenith_deg", "sun_zenith_deg",
                                                   "view_sun_azimuth_deg"};
// "group" is a free-text label (the case set of docs/report.md); the tools
// echo it with the other input columns.
const std::vector<std::string> kOptionalColumns = {"distance_m", "normal_zenith_deg", "group"};

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

bool Blank(const std::string& line) { return line.find_first_not_of(" \t\r") == std::string::npos; }

bool Contains(const std::vector<std::string>& list, const std::string& name) {
  return std::find(list.begin(), list.end(), name) != list.end();
}

}  // namespace

std::string WavelengthName(double nm) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), nm == std::round(nm) ? "%.0fnm" : "%gnm", nm);
  return buffer;
}

ChannelNames WavelengthChannels(const Spectrum& wavelengths_nm) {
  ChannelNames names;
  for (int c = 0; c < kWavelengthCount; ++c) names[c] = WavelengthName(wavelengths_nm[c]);
  return names;
}

ChannelNames XyzChannels() { return {"X", "Y", "Z"}; }

ChannelNames TableChannels(const LutSet& luts) {
  return luts.colour ? XyzChannels() : WavelengthChannels(luts.atmosphere.wavelengths_nm);
}

size_t QueryTable::ResultColumn(const std::string& name) const {
  auto it = std::find(result_columns.begin(), result_columns.end(), name);
  if (it == result_columns.end()) throw InputError(source_name + ": missing column '" + name + "'");
  return static_cast<size_t>(it - result_columns.begin());
}

QueryTable ParseQueryCsv(const std::string& text, const std::string& source_name, ExtraColumns extra_columns) {
  QueryTable table;
  table.source_name = source_name;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  while (table.header.empty() && std::getline(in, line)) {
    ++line_number;
    if (!Blank(line)) table.header = SplitCsvLine(line);
  }
  if (table.header.empty()) throw InputError(source_name + ": empty query file (expected a header line)");
  std::map<std::string, size_t> column;
  for (size_t i = 0; i < table.header.size(); ++i) {
    const std::string& name = table.header[i];
    const std::string where = LocationPrefix(source_name, line_number);
    if (column.count(name) || Contains(table.result_columns, name)) {
      throw InputError(where + "duplicate column '" + name + "'", {source_name, line_number, name});
    }
    if (Contains(kRequiredColumns, name) || Contains(kOptionalColumns, name)) {
      column[name] = i;
    } else if (extra_columns == ExtraColumns::kKeepAsResults) {
      table.result_columns.push_back(name);
    } else {
      throw InputError(where + "unknown column '" + name + "'", {source_name, line_number, name});
    }
  }
  for (const std::string& name : kRequiredColumns) {
    if (!column.count(name)) {
      throw InputError(LocationPrefix(source_name) + "missing column '" + name + "'", {source_name, 0, name});
    }
  }
  table.has_distance = column.count("distance_m") > 0;
  table.has_normal = column.count("normal_zenith_deg") > 0;
  table.has_group = column.count("group") > 0;

  while (std::getline(in, line)) {
    ++line_number;
    if (Blank(line)) continue;
    std::vector<std::string> fields = SplitCsvLine(line);
    auto fail = [&](const std::string& problem) {
      throw InputError(LocationPrefix(source_name, line_number) + problem, {source_name, line_number});
    };
    if (fields.size() != table.header.size()) {
      fail("expected " + std::to_string(table.header.size()) + " fields, got " + std::to_string(fields.size()));
    }
    auto number = [&](const std::string& name, bool optional) {
      const std::string& field = fields[column.at(name)];
      if (field.empty()) {
        if (!optional) fail(name + " is empty");
        return 0.0;
      }
      char* end = nullptr;
      double value = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || *end != '\0') fail(name + " = '" + field + "' is not a number");
      if (!std::isfinite(value)) fail(name + " = " + field + " is not finite");
      return value;
    };
    auto angle = [&](const std::string& name, bool optional) {
      double value = number(name, optional);
      if (value < 0.0 || value > 180.0) fail(name + " = " + fields[column.at(name)] + " is outside [0, 180]");
      return value;
    };
    auto bounded_length = [&](const std::string& name, bool optional) {
      double value = number(name, optional);
      if (value > kMaxLengthM) fail(name + " = " + fields[column.at(name)] + " is beyond 1e12 m");
      return value;
    };
    Query q;
    // A camera below the ground is evaluated on the ground, as by `skybake eval`.
    q.altitude_m = std::max(bounded_length("altitude_m", false), 0.0);
    q.view_zenith_deg = angle("view_zenith_deg", false);
    q.sun_zenith_deg = angle("sun_zenith_deg", false);
    q.view_sun_azimuth_deg = number("view_sun_azimuth_deg", false);
    if (table.has_distance) {
      q.distance_m = bounded_length("distance_m", true);
      if (q.distance_m < 0.0) fail("distance_m = " + fields[column.at("distance_m")] + " is negative");
    }
    if (table.has_normal && !fields[column.at("normal_zenith_deg")].empty()) {
      q.has_normal = true;
      q.normal_zenith_deg = angle("normal_zenith_deg", true);
    }
    if (table.has_group) table.groups.push_back(fields[column.at("group")]);
    std::vector<double> results;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (!Contains(table.result_columns, table.header[i])) continue;
      if (fields[i].empty()) {  // not computed for this row (e.g. irradiance without a normal)
        results.push_back(std::numeric_limits<double>::quiet_NaN());
        continue;
      }
      char* end = nullptr;
      double value = std::strtod(fields[i].c_str(), &end);
      if (*end != '\0') fail(table.header[i] + " = '" + fields[i] + "' is not a number");
      results.push_back(value);
    }
    if (!table.result_columns.empty()) table.results.push_back(results);
    table.fields.push_back(fields);
    table.queries.push_back(q);
    table.line_numbers.push_back(line_number);
  }
  return table;
}

}  // namespace skybake
