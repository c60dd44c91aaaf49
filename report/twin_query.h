// The one place that turns a query (shaders_runtime/query.h) into a call of
// the CPU twin's sky functions, shared by `skybake eval` and the report's
// table-lookup model (run_time_models.h), and the range of suns the tables
// answer, which `eval` and `render` refuse to leave alike.
#pragma once

#include <string>

#include "shaders_runtime/glsl_shim.h"
#include "shaders_runtime/query.h"
#include "shaders_runtime/twin.h"

namespace skybake::report {

// Sky radiance along the query's view: with distance_m > 0 the aerial
// perspective to the point at that distance (GetSkyRadianceToPoint), else
// the whole ray to the ground or space (GetSkyRadiance). `transmittance`,
// if given, receives the transmittance along the same path.
glsl::vec3 QuerySkyRadiance(const Twin& twin, const Query& q, const QueryGeometry& g, glsl::vec3* transmittance);

// Empty where the tables answer a sun `sun_zenith_deg` from the zenith (0
// to the lowest sun they were baked for, parameters.mu_s_min); otherwise
// what a message says after naming the value: "is outside the tables'
// range 0..102.00 degrees". Past the lowest sun the tables hold no light
// and the lookup clamps to their edge.
std::string SunZenithOutsideTables(const glsl::AtmosphereParameters& parameters, double sun_zenith_deg);

}  // namespace skybake::report
