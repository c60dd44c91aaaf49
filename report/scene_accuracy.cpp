#include "report/scene_accuracy.h"

#include <algorithm>

#include "report/run_time_models.h"
#include "shaders_runtime/twin.h"

namespace skybake::report {

SceneAccuracy MeasureSceneAccuracy(const ReferenceSet& reference, const Scene& scene, const LutSet& scene_tables,
                                   const LutSet& full_tables) {
  const Twin scene_twin(MakeTwinTables(scene_tables)), full_twin(MakeTwinTables(full_tables));
  const char* names[3] = {"radiance", "sun_irradiance", "sky_irradiance"};
  std::vector<ErrorSample> scene_samples[3], full_samples[3];
  SceneAccuracy accuracy;
  accuracy.reference = reference.source_name;
  for (const ReferenceCase& c : reference.cases) {
    Query query = c.query;
    std::vector<std::string> unused;
    if (!SceneQueryProblem(scene, scene_tables.atmosphere.bottom_radius_m, false, &query, &unused).empty()) continue;
    ++accuracy.cases;
    if (std::find(accuracy.groups.begin(), accuracy.groups.end(), c.group) == accuracy.groups.end()) {
      accuracy.groups.push_back(c.group);
    }
    const ModelAnswer a = EvaluateTwin(scene_twin, c), b = EvaluateTwin(full_twin, c);
    auto add = [&](int quantity, const glm::dvec3& scene_value, const glm::dvec3& full_value,
                   const glm::dvec3& reference_value, const glm::dvec3& standard_error) {
      for (int k = 0; k < 3; ++k) {
        scene_samples[quantity].push_back({scene_value[k], reference_value[k], standard_error[k]});
        full_samples[quantity].push_back({full_value[k], reference_value[k], standard_error[k]});
      }
    };
    if (c.query.has_normal) {
      add(1, a.sun_irradiance, b.sun_irradiance, c.sun_irradiance, glm::dvec3(0.0));
      add(2, a.sky_irradiance, b.sky_irradiance, c.sky_irradiance, c.sky_irradiance_standard_error);
    } else {
      add(0, a.radiance, b.radiance, c.radiance, c.radiance_standard_error);
    }
  }
  for (int q = 0; q < 3; ++q) {
    if (scene_samples[q].empty()) continue;
    accuracy.quantities.push_back({names[q], ComputeErrorStats(scene_samples[q]), ComputeErrorStats(full_samples[q])});
  }
  return accuracy;
}

}  // namespace skybake::report
