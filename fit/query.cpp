#include "fit/query.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "core/errors.h"
#include "fit/forms.h"
#include "fit/optical_path.h"

namespace skybake::fit {

namespace {

std::string Trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  size_t b = s.find_last_not_of(" \t\r");
  return s.substr(a, b - a + 1);
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(Trim(field));
  if (!line.empty() && line.back() == ',') fields.push_back("");
  for (std::string& f : fields)
    if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
  return fields;
}

std::string Where(const std::string& source, int line) { return source + ":" + std::to_string(line) + ": "; }

double ParseNumber(const std::string& field, const char* column, const std::string& where) {
  if (field.empty()) throw InputError(where + column + " is empty");
  errno = 0;
  char* end = nullptr;
  double v = std::strtod(field.c_str(), &end);
  if (end != field.c_str() + field.size() || errno == ERANGE || !std::isfinite(v))
    throw InputError(where + column + " '" + field + "' is not a finite number");
  return v;
}

std::string Number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.10g", v);
  return buffer;
}

}  // namespace

std::vector<Query> ParseQueryCsv(const std::string& text, const std::string& source_name) {
  std::istringstream in(text);
  std::string line;
  int number = 0;
  int zenith_column = -1, altitude_column = -1;
  size_t columns = 0;
  bool have_header = false;
  std::vector<Query> queries;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line = line.substr(3);  // UTF-8 byte-order mark
    if (Trim(line).empty()) continue;
    std::vector<std::string> fields = SplitFields(line);
    std::string where = Where(source_name, number);
    if (!have_header) {
      for (size_t i = 0; i < fields.size(); ++i) {
        int* slot = fields[i] == "zenith_deg" ? &zenith_column : fields[i] == "altitude_m" ? &altitude_column : nullptr;
        if (!slot) throw InputError(where + "unexpected column '" + fields[i] + "' (expected zenith_deg, altitude_m)");
        if (*slot >= 0) throw InputError(where + "column '" + fields[i] + "' appears twice");
        *slot = static_cast<int>(i);
      }
      if (zenith_column < 0 || altitude_column < 0)
        throw InputError(where + "the header needs the columns zenith_deg and altitude_m");
      columns = fields.size();
      have_header = true;
      continue;
    }
    if (fields.size() != columns)
      throw InputError(where + "expected " + std::to_string(columns) + " fields, found " +
                       std::to_string(fields.size()));
    Query q;
    q.zenith_deg = ParseNumber(fields[zenith_column], "zenith_deg", where);
    q.altitude_m = ParseNumber(fields[altitude_column], "altitude_m", where);
    q.line = number;
    if (q.zenith_deg < 0.0 || q.zenith_deg > 90.0)
      throw InputError(where + "zenith_deg = " + fields[zenith_column] +
                       " is outside [0, 90] (rays below the horizon are not fitted)");
    queries.push_back(q);
  }
  if (!have_header) throw InputError(source_name + ": empty query file (a header zenith_deg,altitude_m is required)");
  return queries;
}

void CheckQueries(const std::vector<Query>& queries, const Atmosphere& atmosphere, const std::string& source_name) {
  double thickness = atmosphere.top_radius_m - atmosphere.bottom_radius_m;
  for (const Query& q : queries) {
    if (q.altitude_m < 0.0 || q.altitude_m > thickness)
      throw InputError(Where(source_name, q.line) + "altitude_m = " + Number(q.altitude_m) +
                       " is outside the atmosphere [0, " + Number(thickness) + "]");
  }
}

std::string AnswerQueries(const std::vector<Query>& queries, const Atmosphere& atmosphere,
                          const Constituent& constituent, const ConstituentFit& fit) {
  ColumnIntegrator integrator(constituent.density, atmosphere.bottom_radius_m, atmosphere.top_radius_m);
  std::string out = "zenith_deg,altitude_m,exact,fitted,iqbal\n";
  for (const Query& q : queries) {
    double mu = q.zenith_deg >= 90.0 ? 0.0 : std::cos(q.zenith_deg * 0.017453292519943295);
    std::optional<double> exact = integrator.Sample(q.altitude_m, mu).RelativeOpticalPath();
    out += Number(q.zenith_deg) + "," + Number(q.altitude_m) + "," + (exact ? Number(*exact) : "") + "," +
           (fit.fitted ? Number(fit.surface.RelativeOpticalPath(mu, q.altitude_m)) : "") + "," +
           Number(IqbalRelativeOpticalPath(mu)) + "\n";
  }
  return out;
}

}  // namespace skybake::fit
