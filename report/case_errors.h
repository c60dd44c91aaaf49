// The reference values of `skybake report` and the errors of a model (a
// baked table set, a run-time model) on them, per case group.
//
// The reference file is a `skybake reference` output over a case set with a
// `group` column (reference/cases/earth_reference.csv, docs/report.md): sky
// radiance with its standard error per wavelength, and for rows with a
// surface normal, sun and sky irradiance. The groups measured are the case
// groups for radiance, except that irradiance rows are measured twice, as
// "sun_irradiance" and "sky_irradiance".
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bake/atmosphere.h"
#include "formats/query_csv.h"
#include "report/error_stats.h"
#include "shaders_runtime/query.h"

namespace skybake::report {

struct ReferenceCase {
  std::string group;
  Query query;
  glm::dvec3 radiance{0.0}, radiance_standard_error{0.0};
  glm::dvec3 sun_irradiance{0.0};  // computed from transmittance: no Monte Carlo noise
  glm::dvec3 sky_irradiance{0.0}, sky_irradiance_standard_error{0.0};
};

struct ReferenceSet {
  std::string source_name;
  std::vector<ReferenceCase> cases;
};

// InputError naming the source for a file without a group column, or
// without the per-wavelength columns of `atmosphere`'s wavelengths (a
// reference computed for another atmosphere).
ReferenceSet ParseReference(const std::string& text, const std::string& source_name, const Atmosphere& atmosphere);
// The same for a reference whose columns are named by `channels` (XYZ for a
// spectral reference); `expected` says what it should be in the error
// ("a reference for earth").
ReferenceSet ParseReference(const std::string& text, const std::string& source_name, const ChannelNames& channels,
                            const std::string& expected);

// The reference in `file`, or where `file` is empty the one committed for
// `atmosphere` (reference_files.h); nullopt if there is none.
std::optional<ReferenceSet> LoadReference(const std::string& file, const Atmosphere& atmosphere);
// Every reference committed for `atmosphere` over all orders at its own
// wavelengths, as one set: the general cases (<name>_reference.csv) and the
// case sets kCommittedCaseSets names (<name>_<set>_reference.csv), their
// source names joined by ", "; nullopt if none is committed. (Not the
// single-scattering nor the spectral references.)
inline constexpr const char* kCommittedCaseSets[] = {"twilight", "twilight_between", "aerial_horizon"};
std::optional<ReferenceSet> LoadCommittedCaseSets(const Atmosphere& atmosphere);

// What a model answers for one case; a model that cannot answer a quantity
// (a ray march has no sky irradiance, Hoffman & Preetham no view from space)
// leaves it unset.
struct ModelAnswer {
  bool has_radiance = false;
  glm::dvec3 radiance{0.0};
  bool has_sun_irradiance = false;
  glm::dvec3 sun_irradiance{0.0};
  bool has_sky_irradiance = false;
  glm::dvec3 sky_irradiance{0.0};
};

using Model = std::function<ModelAnswer(const ReferenceCase&)>;

struct GroupErrors {
  std::string group;
  ErrorStats channel[3];  // per wavelength
  ErrorStats luminance;
  int unanswered = 0;     // cases of the group the model did not answer
  // Every case answered: a model that leaves some out is "n/a" for the group.
  bool Answered() const { return unanswered == 0 && luminance.count + luminance.skipped > 0; }
};

// Groups in the order they first appear in the cases.
std::vector<std::string> MeasuredGroups(const ReferenceSet& reference);

// One entry per MeasuredGroups() entry.
std::vector<GroupErrors> MeasureErrors(const ReferenceSet& reference, const Model& model);

// The entry for `group`; InternalError if there is none.
const GroupErrors& FindGroup(const std::vector<GroupErrors>& errors, const std::string& group);

}  // namespace skybake::report
