// Query files shared by every command that answers queries (`skybake eval`,
// `skybake reference`): CSV with the header columns altitude_m,
// view_zenith_deg, sun_zenith_deg, view_sun_azimuth_deg and optionally
// distance_m, normal_zenith_deg and a free-text group label, in any order
// (docs/eval.md, docs/report.md). Files are CSV as RFC 4180 writes it (a
// field in double quotes may hold commas, line breaks and doubled quotes),
// their numbers decimal (no hexadecimal, inf or nan).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "shaders_runtime/query.h"

namespace skybake {

struct QueryTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> fields;  // per row, as written (unquoted)
  std::vector<Query> queries;                      // per row; altitude below 0 raised to 0
  std::vector<int> line_numbers;                   // per row: the 1-based line it starts on
  bool has_distance = false;
  bool has_normal = false;
  bool has_group = false;
  std::vector<std::string> groups;                 // per row, when has_group
  // With ExtraColumns::kKeepAsResults: every other column, parsed as a number; an
  // empty field (a value not computed for that row) is NaN.
  std::vector<std::string> result_columns;
  std::vector<std::vector<double>> results;  // per row, per result column
  // The index of a result column; InputError naming SOURCE when it is missing.
  size_t ResultColumn(const std::string& name) const;
  std::string source_name;
};

// What to do with columns that are not query columns: a query file rejects
// them; a results file (eval or reference output read back, e.g. the report's
// reference values) keeps them as numbers.
enum class ExtraColumns { kReject, kKeepAsResults };

// InputError "SOURCE:LINE: problem" on a malformed file, located at the
// column (ErrorLocation::key) where the problem is one field's.
QueryTable ParseQueryCsv(const std::string& text, const std::string& source_name,
                         ExtraColumns extra_columns = ExtraColumns::kReject);

// `value` as a CSV field: in double quotes (quotes doubled) where it holds a
// comma, a quote or a line break, or begins or ends with a space or tab.
std::string CsvField(const std::string& value);
// The input columns of `row` as a CSV line (no line break), each field as
// CsvField writes it: how the tools echo a query.
std::string CsvInputColumns(const QueryTable& table, size_t row);

// "680nm" for 680, "532.5nm" for 532.5: the suffix of per-wavelength columns.
std::string WavelengthName(double nm);

// The suffixes of per-channel columns: a wavelength's name per channel, or
// "X", "Y", "Z" for a spectral bake or reference (bake/spectral.h).
using ChannelNames = std::array<std::string, kWavelengthCount>;
ChannelNames WavelengthChannels(const Spectrum& wavelengths_nm);
ChannelNames XyzChannels();
// A table set's: XYZ when it is spectral.
ChannelNames TableChannels(const LutSet& luts);

}  // namespace skybake
