// The report's fixed case set (reference/cases/earth.csv, docs/report.md) and
// the committed reference values for it: the file follows its documented
// rule, and the reference is precise enough for the accuracy targets it is
// used for.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <string>

#include "bake/config.h"
#include "core/errors.h"
#include "formats/query_csv.h"
#include "test_util.h"

namespace skybake {
namespace {

const std::string kCases = std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/earth.csv";
const std::string kReference = std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/earth_reference.csv";

TEST(QueryCsvGroups, GroupLabelsAndResultColumnsAreKept) {
  const std::string text =
      "group,altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,radiance_680nm,sky_irradiance_680nm\n"
      "daylight,0,0,30,0,0.25,\n";
  EXPECT_THROW(ParseQueryCsv(text, "r.csv"), InputError);  // a query file has no result columns
  QueryTable table = ParseQueryCsv(text, "r.csv", ExtraColumns::kKeepAsResults);
  ASSERT_TRUE(table.has_group);
  ASSERT_EQ(table.groups.size(), 1u);
  EXPECT_EQ(table.groups[0], "daylight");
  ASSERT_EQ(table.result_columns.size(), 2u);
  EXPECT_EQ(table.results[0][table.ResultColumn("radiance_680nm")], 0.25);
  EXPECT_TRUE(std::isnan(table.results[0][table.ResultColumn("sky_irradiance_680nm")]));  // empty: not computed
  EXPECT_THROW(table.ResultColumn("radiance_550nm"), InputError);
  EXPECT_THROW(ParseQueryCsv("altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,x\n0,0,30,0,y\n",
                             "r.csv", ExtraColumns::kKeepAsResults),
               InputError);
}

TEST(ReportCases, FollowTheDocumentedRule) {
  QueryTable cases = ParseQueryCsv(testing::ReadText(kCases), "earth.csv");
  ASSERT_TRUE(cases.has_group && cases.has_distance && cases.has_normal);
  EXPECT_GE(cases.queries.size(), 200u);
  const double top_altitude_m = LoadPreset("earth").top_radius_m - LoadPreset("earth").bottom_radius_m;
  std::map<std::string, int> count;
  for (size_t i = 0; i < cases.queries.size(); ++i) {
    const Query& q = cases.queries[i];
    const std::string& group = cases.groups[i];
    ++count[group];
    SCOPED_TRACE("row " + std::to_string(i + 2) + " (" + group + ")");
    EXPECT_EQ(q.distance_m > 0.0, group == "aerial_perspective");
    EXPECT_EQ(q.has_normal, group == "irradiance");
    if (group == "daylight" || group == "horizon") {
      EXPECT_LE(q.sun_zenith_deg, 80.0);
    } else if (group == "twilight") {
      EXPECT_GT(q.sun_zenith_deg, 80.0);
      EXPECT_LE(q.sun_zenith_deg, 100.0);
    } else if (group == "space") {
      EXPECT_GT(q.altitude_m, top_altitude_m);
    } else if (group == "aerial_perspective") {
      EXPECT_GE(q.distance_m, 1000.0);
      EXPECT_LE(q.distance_m, 100000.0);
    } else {
      EXPECT_EQ(group, "irradiance");
    }
  }
  for (const char* group : {"daylight", "horizon", "twilight", "space", "aerial_perspective", "irradiance"}) {
    EXPECT_GT(count[group], 0) << group;
  }
  // Views from 1, 10 and 100 km; near-horizontal aerial perspective at the ground.
  std::set<double> altitudes;
  bool short_horizontal_segment = false;
  for (const Query& q : cases.queries) {
    altitudes.insert(q.altitude_m);
    short_horizontal_segment |= q.distance_m > 0.0 && q.distance_m <= 1000.0 && q.view_zenith_deg == 90.0;
  }
  for (double altitude : {1000.0, 10000.0, 100000.0}) EXPECT_EQ(altitudes.count(altitude), 1u) << altitude;
  EXPECT_TRUE(short_horizontal_segment);
}

// The committed reference answers exactly the case set, with finite,
// non-negative values, and its standard error on the daylight sky is at most
// 0.3% per wavelength: a third of the 1% RMS target the tables are held to,
// so the reference's noise cannot hide a miss of that target.
TEST(ReportCases, ReferenceCoversTheCasesWithSmallDaylightNoise) {
  QueryTable cases = ParseQueryCsv(testing::ReadText(kCases), "earth.csv");
  QueryTable ref = ParseQueryCsv(testing::ReadText(kReference), "earth_reference.csv", ExtraColumns::kKeepAsResults);
  ASSERT_EQ(ref.header.size(), cases.header.size() + ref.result_columns.size());
  ASSERT_EQ(ref.fields.size(), cases.fields.size());
  for (size_t i = 0; i < cases.fields.size(); ++i) {
    for (size_t c = 0; c < cases.header.size(); ++c) EXPECT_EQ(ref.fields[i][c], cases.fields[i][c]) << "row " << i;
  }
  double worst_daylight = 0.0;
  for (size_t i = 0; i < ref.queries.size(); ++i) {
    for (size_t c = 0; c < ref.result_columns.size(); ++c) {
      double v = ref.results[i][c];
      bool irradiance_column = ref.result_columns[c].find("irradiance") != std::string::npos;
      if (irradiance_column && !ref.queries[i].has_normal) continue;  // empty: not computed
      EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << "row " << i << " " << ref.result_columns[c] << " = " << v;
    }
    if (ref.groups[i] != "daylight") continue;
    for (const char* nm : {"680nm", "550nm", "440nm"}) {
      double radiance = ref.results[i][ref.ResultColumn(std::string("radiance_") + nm)];
      double standard_error = ref.results[i][ref.ResultColumn(std::string("radiance_stderr_") + nm)];
      ASSERT_GT(radiance, 0.0) << "row " << i;
      worst_daylight = std::max(worst_daylight, standard_error / radiance);
    }
  }
  EXPECT_LE(worst_daylight, 0.003);
}

// A twilight case set (reference/cases/NAME.csv) and its reference
// (NAME_reference.csv): the reference has every case, and standard errors
// no larger than those it was committed with, per group, for the quantity
// `stated` names (the largest relative standard error of any channel).
void ExpectReferenceCoversItsCasesWithItsStatedNoise(
    const std::string& name, const std::map<std::string, std::pair<std::string, double>>& stated) {
  const std::string cases_path = std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/" + name + ".csv";
  const std::string reference_path = std::string(SKYBAKE_SOURCE_DIR) + "/reference/cases/" + name + "_reference.csv";
  QueryTable cases = ParseQueryCsv(testing::ReadText(cases_path), name + ".csv");
  QueryTable ref = ParseQueryCsv(testing::ReadText(reference_path), name + "_reference.csv",
                                 ExtraColumns::kKeepAsResults);
  ASSERT_EQ(ref.fields.size(), cases.fields.size());
  for (size_t i = 0; i < cases.fields.size(); ++i) {
    for (size_t c = 0; c < cases.header.size(); ++c) EXPECT_EQ(ref.fields[i][c], cases.fields[i][c]) << "row " << i;
  }
  std::map<std::string, double> worst;
  for (size_t i = 0; i < ref.queries.size(); ++i) {
    const auto bound = stated.find(ref.groups[i]);
    ASSERT_NE(bound, stated.end()) << ref.groups[i];
    const std::string& quantity = bound->second.first;
    for (const char* nm : {"680nm", "550nm", "440nm"}) {
      const double value = ref.results[i][ref.ResultColumn(quantity + "_" + nm)];
      const double standard_error = ref.results[i][ref.ResultColumn(quantity + "_stderr_" + nm)];
      ASSERT_TRUE(std::isfinite(value) && value >= 0.0) << "row " << i << " " << quantity << " " << nm;
      if (value == 0.0) {  // the ray misses the atmosphere (from space): exactly dark, exactly known
        EXPECT_EQ(standard_error, 0.0) << "row " << i;
        continue;
      }
      worst[ref.groups[i]] = std::max(worst[ref.groups[i]], standard_error / value);
    }
  }
  for (const auto& [group, bound] : stated) {
    std::printf("%s: largest relative standard error %.3g\n", group.c_str(), worst[group]);
    EXPECT_LE(worst[group], bound.second) << group;
  }
}

// The dense twilight set (scripts/make_cases.py twilight, docs/accuracy.md):
// 1 % to sun 100 degrees and 3 % beyond, what it is computed for.
TEST(ReportCases, TwilightReferenceCoversItsCasesWithItsStatedNoise) {
  ExpectReferenceCoversItsCasesWithItsStatedNoise("earth_twilight",
                                                  {{"twilight_sky_sun_88-90", {"radiance", 0.01}},
                                                   {"twilight_sky_sun_91-96", {"radiance", 0.01}},
                                                   {"twilight_sky_sun_97-100", {"radiance", 0.01}},
                                                   {"twilight_sky_sun_101-102", {"radiance", 0.03}},
                                                   {"twilight_irradiance_sun_88-100", {"sky_irradiance", 0.01}},
                                                   {"low_sun_aerial_perspective_sun_84-90", {"radiance", 0.01}}});
}

// The twilight set between whole degrees (scripts/make_cases.py
// twilight-between): 1 %, with the same paths per sun as the dense set.
TEST(ReportCases, TwilightBetweenDegreesReferenceCoversItsCasesWithItsStatedNoise) {
  ExpectReferenceCoversItsCasesWithItsStatedNoise("earth_twilight_between",
                                                  {{"twilight_between_sun_90-93", {"radiance", 0.01}},
                                                   {"twilight_between_sun_94-96", {"radiance", 0.01}},
                                                   {"twilight_between_sun_97-99", {"radiance", 0.01}}});
}

}  // namespace
}  // namespace skybake
