#include "formats/query_csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>

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

// The records of a CSV text as RFC 4180 writes them: fields separated by
// commas, records by line breaks (LF or CRLF); a field in double quotes may
// hold commas, line breaks and quotes (written twice). Spaces and tabs
// around a field are not part of it; blank lines are skipped.
class CsvRecords {
 public:
  CsvRecords(const std::string& text, const std::string& source_name) : text_(text), source_name_(source_name) {}

  // The next record's fields and the line it starts on; false at the end.
  bool Next(std::vector<std::string>* fields, int* line_number) {
    for (;;) {
      if (at_ >= text_.size()) return false;
      *line_number = line_;
      fields->clear();
      bool blank = true;
      for (;;) {
        SkipSpaces();
        std::string field;
        if (at_ < text_.size() && text_[at_] == '"') {
          blank = false;
          field = QuotedField(fields->size() + 1);
        } else {
          const std::size_t begin = at_;
          while (at_ < text_.size() && text_[at_] != ',' && text_[at_] != '\n' && text_[at_] != '\r') ++at_;
          field = text_.substr(begin, at_ - begin);
          field.erase(field.find_last_not_of(" \t") + 1);
          if (field.find('"') != std::string::npos) {
            Fail(fields->size() + 1, "a quote inside an unquoted field (quote the whole field and double the quote)");
          }
        }
        if (!field.empty()) blank = false;
        fields->push_back(std::move(field));
        if (at_ < text_.size() && text_[at_] == ',') {
          blank = false;
          ++at_;
          continue;
        }
        break;
      }
      EndOfRecord();
      if (!blank) return true;
    }
  }

 private:
  void SkipSpaces() {
    while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\t')) ++at_;
  }

  // A field from its opening quote to its closing one; `field_number`, from
  // 1, for messages.
  std::string QuotedField(std::size_t field_number) {
    const int opened_on = line_;
    std::string field;
    for (++at_;; ++at_) {
      if (at_ >= text_.size()) {
        line_ = opened_on;
        Fail(field_number, "a quoted field is not closed (a \" is missing)");
      }
      const char c = text_[at_];
      if (c == '"') {
        if (at_ + 1 < text_.size() && text_[at_ + 1] == '"') {
          field += '"';
          ++at_;
          continue;
        }
        ++at_;
        break;
      }
      if (c == '\n') ++line_;
      field += c;
    }
    SkipSpaces();
    if (at_ < text_.size() && text_[at_] != ',' && text_[at_] != '\n' && text_[at_] != '\r') {
      Fail(field_number, "text after the closing quote of a quoted field");
    }
    return field;
  }

  void EndOfRecord() {
    if (at_ < text_.size() && text_[at_] == '\r') ++at_;
    if (at_ < text_.size() && text_[at_] == '\n') ++at_, ++line_;
  }

  [[noreturn]] void Fail(std::size_t field_number, const std::string& problem) const {
    const std::string key = "field " + std::to_string(field_number);
    throw InputError(LocationPrefix(source_name_, line_) + key + ": " + problem, {source_name_, line_, key});
  }

  const std::string& text_;
  const std::string& source_name_;
  std::size_t at_ = 0;
  int line_ = 1;
};

// A decimal number, as a CSV file of numbers writes one: an optional sign,
// digits with an optional decimal point, an optional exponent (e or E, an
// optional sign, digits). std::strtod alone would also read hexadecimal
// ("0x10"), "inf" and "nan".
bool ParseDecimal(const std::string& text, double* value) {
  std::size_t i = 0;
  const std::size_t n = text.size();
  auto sign = [&] {
    if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  };
  auto digits = [&] {
    const std::size_t first = i;
    while (i < n && text[i] >= '0' && text[i] <= '9') ++i;
    return i - first;
  };
  sign();
  std::size_t mantissa_digits = digits();
  if (i < n && text[i] == '.') {
    ++i;
    mantissa_digits += digits();
  }
  if (mantissa_digits == 0) return false;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    sign();
    if (digits() == 0) return false;
  }
  if (i != n) return false;
  *value = std::strtod(text.c_str(), nullptr);
  return true;
}

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
  CsvRecords records(text, source_name);
  int line_number = 0;
  if (!records.Next(&table.header, &line_number)) {
    throw InputError(source_name + ": empty query file (expected a header line)");
  }
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

  std::vector<std::string> fields;
  while (records.Next(&fields, &line_number)) {
    // "FILE:LINE: problem", located at the column named (if any).
    auto fail = [&](const std::string& problem, const std::string& name = {}) {
      throw InputError(LocationPrefix(source_name, line_number) + problem, {source_name, line_number, name});
    };
    if (fields.size() != table.header.size()) {
      fail("expected " + std::to_string(table.header.size()) + " fields, got " + std::to_string(fields.size()));
    }
    // The decimal number in column `name`; NaN where it is empty and `empty_is_nan`.
    auto decimal = [&](const std::string& name, const std::string& field, bool empty_is_nan) {
      if (field.empty()) {
        if (!empty_is_nan) fail(name + " is empty", name);
        return std::numeric_limits<double>::quiet_NaN();
      }
      double value = 0.0;
      if (!ParseDecimal(field, &value)) {
        fail(name + " = '" + field + "' is not a number (write it in decimal: 16, 0.5, 1e-3)", name);
      }
      if (!std::isfinite(value)) fail(name + " = " + field + " is not finite", name);
      return value;
    };
    auto number = [&](const std::string& name, bool optional) {
      const std::string& field = fields[column.at(name)];
      if (optional && field.empty()) return 0.0;
      return decimal(name, field, false);
    };
    auto angle = [&](const std::string& name, bool optional) {
      double value = number(name, optional);
      if (value < 0.0 || value > 180.0) fail(name + " = " + fields[column.at(name)] + " is outside [0, 180]", name);
      return value;
    };
    auto bounded_length = [&](const std::string& name, bool optional) {
      double value = number(name, optional);
      if (value > kMaxLengthM) fail(name + " = " + fields[column.at(name)] + " is beyond 1e12 m", name);
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
      if (q.distance_m < 0.0) fail("distance_m = " + fields[column.at("distance_m")] + " is negative", "distance_m");
    }
    if (table.has_normal && !fields[column.at("normal_zenith_deg")].empty()) {
      q.has_normal = true;
      q.normal_zenith_deg = angle("normal_zenith_deg", true);
    }
    if (table.has_group) table.groups.push_back(fields[column.at("group")]);
    std::vector<double> results;
    for (size_t i = 0; i < fields.size(); ++i) {
      // An empty result: not computed for this row (e.g. irradiance without a normal).
      if (Contains(table.result_columns, table.header[i])) results.push_back(decimal(table.header[i], fields[i], true));
    }
    if (!table.result_columns.empty()) table.results.push_back(results);
    table.fields.push_back(fields);
    table.queries.push_back(q);
    table.line_numbers.push_back(line_number);
  }
  return table;
}

std::string CsvField(const std::string& value) {
  const bool plain = value.find_first_of(",\"\r\n") == std::string::npos &&
                     (value.empty() || (value.front() != ' ' && value.front() != '\t' && value.back() != ' ' &&
                                        value.back() != '\t'));
  if (plain) return value;
  std::string quoted = "\"";
  for (char c : value) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string CsvInputColumns(const QueryTable& table, size_t row) {
  std::string line;
  for (size_t i = 0; i < table.fields[row].size(); ++i) line += (i ? "," : "") + CsvField(table.fields[row][i]);
  return line;
}

}  // namespace skybake
