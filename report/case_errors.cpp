#include "report/case_errors.h"

#include <algorithm>

#include "bake/config.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/query_csv.h"
#include "report/reference_files.h"

namespace skybake::report {

namespace {

constexpr const char* kSunIrradiance = "sun_irradiance";
constexpr const char* kSkyIrradiance = "sky_irradiance";

}  // namespace

ReferenceSet ParseReference(const std::string& text, const std::string& source_name, const Atmosphere& atmosphere) {
  return ParseReference(text, source_name, WavelengthChannels(atmosphere.wavelengths_nm),
                        "a reference for " + atmosphere.name);
}

ReferenceSet ParseReference(const std::string& text, const std::string& source_name, const ChannelNames& channels,
                            const std::string& expected) {
  QueryTable table = ParseQueryCsv(text, source_name, ExtraColumns::kKeepAsResults);
  if (!table.has_group) throw InputError(source_name + ": a reference file needs a group column (docs/report.md)");
  auto columns = [&](const std::string& quantity) {
    std::vector<size_t> indices;
    for (const std::string& name : channels) {
      auto it = std::find(table.result_columns.begin(), table.result_columns.end(), quantity + name);
      if (it == table.result_columns.end()) {
        throw InputError(source_name + ": no column " + quantity + name + ": not " + expected +
                         " (compute one with skybake reference and pass it with --reference)");
      }
      indices.push_back(static_cast<size_t>(it - table.result_columns.begin()));
    }
    return indices;
  };
  auto radiance = columns("radiance_"), radiance_error = columns("radiance_stderr_");
  std::vector<size_t> sun, sky, sky_error;
  if (table.has_normal) {
    sun = columns("sun_irradiance_");
    sky = columns("sky_irradiance_");
    sky_error = columns("sky_irradiance_stderr_");
  }
  ReferenceSet set;
  set.source_name = source_name;
  for (size_t row = 0; row < table.queries.size(); ++row) {
    ReferenceCase c;
    c.group = table.groups[row];
    c.query = table.queries[row];
    const std::vector<double>& values = table.results[row];
    for (int k = 0; k < kWavelengthCount; ++k) {
      c.radiance[k] = values[radiance[k]];
      c.radiance_standard_error[k] = values[radiance_error[k]];
      if (c.query.has_normal) {
        c.sun_irradiance[k] = values[sun[k]];
        c.sky_irradiance[k] = values[sky[k]];
        c.sky_irradiance_standard_error[k] = values[sky_error[k]];
      }
    }
    set.cases.push_back(c);
  }
  if (set.cases.empty()) throw InputError(source_name + ": no reference values");
  return set;
}

std::optional<ReferenceSet> LoadReference(const std::string& file, const Atmosphere& atmosphere) {
  if (!file.empty()) {
    return ParseReference(ReadFileText(file), InputName(file), atmosphere);
  }
  const EmbeddedText* committed = CommittedReference(atmosphere.name);
  if (!committed) return std::nullopt;
  return ParseReference(std::string(committed->text), std::string(committed->name), atmosphere);
}

std::optional<ReferenceSet> LoadCommittedCaseSets(const Atmosphere& atmosphere) {
  std::optional<ReferenceSet> all;
  auto add = [&](const std::string& name) {
    const EmbeddedText* committed = CommittedReference(name);
    if (!committed) return;
    ReferenceSet set = ParseReference(std::string(committed->text), std::string(committed->name), atmosphere);
    if (!all) {
      all = std::move(set);
      return;
    }
    all->source_name += ", " + set.source_name;
    all->cases.insert(all->cases.end(), set.cases.begin(), set.cases.end());
  };
  add(atmosphere.name);
  for (const char* set : kCommittedCaseSets) add(atmosphere.name + "_" + set);
  return all;
}

std::vector<std::string> MeasuredGroups(const ReferenceSet& reference) {
  std::vector<std::string> groups;
  auto add = [&](const std::string& g) {
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
  };
  for (const ReferenceCase& c : reference.cases) {
    if (c.query.has_normal) {
      add(kSunIrradiance);
      add(kSkyIrradiance);
    } else {
      add(c.group);
    }
  }
  return groups;
}

std::vector<GroupErrors> MeasureErrors(const ReferenceSet& reference, const Model& model) {
  std::vector<std::string> groups = MeasuredGroups(reference);
  std::vector<std::vector<ErrorSample>> channel_samples(groups.size() * 3), luminance_samples(groups.size());
  std::vector<GroupErrors> errors(groups.size());
  auto index = [&](const std::string& g) {
    return static_cast<size_t>(std::find(groups.begin(), groups.end(), g) - groups.begin());
  };
  auto add = [&](const std::string& group, bool answered, const glm::dvec3& value, const glm::dvec3& ref,
                 const glm::dvec3& standard_error) {
    size_t g = index(group);
    if (!answered) {
      ++errors[g].unanswered;
      return;
    }
    for (int k = 0; k < 3; ++k) channel_samples[3 * g + k].push_back({value[k], ref[k], standard_error[k]});
    luminance_samples[g].push_back({Luminance(value), Luminance(ref), LuminanceStandardError(standard_error)});
  };
  for (const ReferenceCase& c : reference.cases) {
    ModelAnswer a = model(c);
    if (c.query.has_normal) {
      add(kSunIrradiance, a.has_sun_irradiance, a.sun_irradiance, c.sun_irradiance, glm::dvec3(0.0));
      add(kSkyIrradiance, a.has_sky_irradiance, a.sky_irradiance, c.sky_irradiance,
          c.sky_irradiance_standard_error);
    } else {
      add(c.group, a.has_radiance, a.radiance, c.radiance, c.radiance_standard_error);
    }
  }
  for (size_t g = 0; g < groups.size(); ++g) {
    errors[g].group = groups[g];
    for (int k = 0; k < 3; ++k) errors[g].channel[k] = ComputeErrorStats(channel_samples[3 * g + k]);
    errors[g].luminance = ComputeErrorStats(luminance_samples[g]);
  }
  return errors;
}

const GroupErrors& FindGroup(const std::vector<GroupErrors>& errors, const std::string& group) {
  for (const GroupErrors& e : errors) {
    if (e.group == group) return e;
  }
  throw InternalError("no errors measured for group " + group);
}

}  // namespace skybake::report
