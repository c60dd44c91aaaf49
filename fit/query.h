// `skybake fit --query`: exact, fitted and Iqbal relative optical paths at
// points read from a CSV file.
//
// Input: a header naming the columns zenith_deg and altitude_m (any order,
// no others), then one row per query; blank lines are skipped. Zenith angles
// must lie in [0, 90] (rays below the horizon are not fitted) and altitudes
// inside the atmosphere. Any malformed row is an InputError naming the file
// and line. Output: CSV zenith_deg,altitude_m,exact,fitted,iqbal. `exact`
// is empty where no density lies above the observer (m is 0/0 there);
// `fitted` is empty when the constituent could not be fitted, and otherwise
// evaluates the surface with the altitude clamped to its fitted range.
#pragma once

#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "fit/sky_dome_fit.h"

namespace skybake::fit {

struct Query {
  double zenith_deg = 0.0;
  double altitude_m = 0.0;
  int line = 0;  // 1-based line in the source, for messages
};

std::vector<Query> ParseQueryCsv(const std::string& text, const std::string& source_name);

// Throws InputError (naming the line) for queries outside the atmosphere.
void CheckQueries(const std::vector<Query>& queries, const Atmosphere& atmosphere, const std::string& source_name);

// `fit` may be unfitted (then the fitted column is empty).
std::string AnswerQueries(const std::vector<Query>& queries, const Atmosphere& atmosphere,
                          const Constituent& constituent, const ConstituentFit& fit);

}  // namespace skybake::fit
