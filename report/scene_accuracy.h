// The accuracy of a scene's bake inside its scene, against the full bake:
// the reference cases (case_errors.h) that the scene can answer, as `skybake
// eval` on the scene's tables would accept them, evaluated through the CPU
// twin of each set (skybake bake --scene --compare-full).
#pragma once

#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/scene.h"
#include "report/case_errors.h"
#include "report/error_stats.h"

namespace skybake::report {

struct SceneQuantityErrors {
  std::string quantity;  // "radiance", "sun_irradiance" or "sky_irradiance"
  ErrorStats scene, full;  // over the channels of every case
};

struct SceneAccuracy {
  std::string reference;       // the reference's source name
  int cases = 0;               // inside the scene
  std::vector<std::string> groups;  // their case groups
  std::vector<SceneQuantityErrors> quantities;  // those with cases
};

SceneAccuracy MeasureSceneAccuracy(const ReferenceSet& reference, const Scene& scene, const LutSet& scene_tables,
                                   const LutSet& full_tables);

}  // namespace skybake::report
