#include "reference/query_csv.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "core/errors.h"

namespace skybake::reference {

std::vector<std::string> ResultColumns(const QueryTable& table, const ChannelNames& channels) {
  std::vector<std::string> columns = table.header;
  auto add = [&](const char* quantity) {
    for (int w = 0; w < kWavelengthCount; ++w) columns.push_back(quantity + channels[w]);
  };
  add("radiance_");
  add("radiance_stderr_");
  add("transmittance_");
  if (table.has_normal) {
    add("sun_irradiance_");
    add("sky_irradiance_");
    add("sky_irradiance_stderr_");
  }
  add("transmittance_error_");
  return columns;
}

std::string FormatResultCsv(const QueryTable& table, const std::vector<Result>& results,
                            const ChannelNames& channels) {
  std::string out;
  std::vector<std::string> columns = ResultColumns(table, channels);
  for (size_t i = 0; i < columns.size(); ++i) out += (i ? "," : "") + columns[i];
  out += "\n";
  for (size_t row = 0; row < table.fields.size(); ++row) {
    const Result& result = results.at(row);
    std::string line = CsvInputColumns(table, row);
    auto append = [&](const Spectrum& v) {
      char buffer[64];
      for (int w = 0; w < kWavelengthCount; ++w) {
        std::snprintf(buffer, sizeof(buffer), ",%.9g", v[w]);
        line += buffer;
      }
    };
    append(result.radiance.mean);
    append(result.radiance.standard_error);
    append(result.transmittance);
    if (table.has_normal) {
      if (result.has_irradiance) {
        append(result.sun_irradiance);
        append(result.sky_irradiance.mean);
        append(result.sky_irradiance.standard_error);
      } else {
        line += ",,,,,,,,,";
      }
    }
    append(result.transmittance_error);
    out += line + "\n";
  }
  return out;
}

}  // namespace skybake::reference
