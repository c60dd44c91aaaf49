// Query files shared by every command that answers queries (`skybake eval`,
// `skybake reference`): CSV with the header columns altitude_m,
// view_zenith_deg, sun_zenith_deg, view_sun_azimuth_deg and optionally
// distance_m and normal_zenith_deg, in any order (docs/eval.md).
#pragma once

#include <string>
#include <vector>

#include "shaders_runtime/query.h"

namespace skybake {

struct QueryTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> fields;  // per row, as written
  std::vector<Query> queries;                      // per row; altitude below 0 raised to 0
  bool has_distance = false;
  bool has_normal = false;
};

// InputError "SOURCE:LINE: problem" on a malformed file.
QueryTable ParseQueryCsv(const std::string& text, const std::string& source_name);

// "680nm" for 680, "532.5nm" for 532.5: the suffix of per-wavelength columns.
std::string WavelengthName(double nm);

}  // namespace skybake
