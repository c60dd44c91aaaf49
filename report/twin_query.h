// The one place that turns a query (shaders_runtime/query.h) into a call of
// the CPU twin's sky functions, shared by `skybake eval` and the report's
// table-lookup model (run_time_models.h).
#pragma once

#include "shaders_runtime/glsl_shim.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/twin.h"

namespace skybake::report {

// Sky radiance along the query's view: with distance_m > 0 the aerial
// perspective to the point at that distance (GetSkyRadianceToPoint), else
// the whole ray to the ground or space (GetSkyRadiance). `transmittance`,
// if given, receives the transmittance along the same path.
glsl::vec3 QuerySkyRadiance(const Twin& twin, const Query& q, const QueryGeometry& g, glsl::vec3* transmittance);

}  // namespace skybake::report
