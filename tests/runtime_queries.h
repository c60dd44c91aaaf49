// The queries the runtime tests run on real drivers (GL, Vulkan, WebGPU) in
// each shading language, the CPU twin's answers to them, and the comparison
// with its tolerances: one definition for every language and driver.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "shaders_runtime/glsl_shim.h"

namespace skybake::testing {

// Small tables: the comparison is between two evaluations of the same
// tables, so they test it as well as full ones and bake fast.
BakeSettings RuntimeTestSettings(bool pack_mie);

// What one evaluation returns. Each language's test main() switches on it
// in the same way: 0-1 GetSkyRadiance (radiance, transmittance), 2-3
// GetSkyRadianceToPoint, 4-5 GetSunAndSkyIrradiance (sun, sky), 6
// GetTransmittanceToSun, 7 GetSolarRadiance, 8 GetSkyRadianceToPointWithShadow.
enum RuntimeOutput {
  kSkyRadiance,
  kSkyTransmittance,
  kAerialRadiance,
  kAerialTransmittance,
  kSunIrradiance,
  kSkyIrradiance,
  kTransmittanceToSun,
  kSolarRadiance,
  kAerialRadianceInShadow,
  kOutputCount
};

struct RuntimeQuery {
  int what;  // RuntimeOutput
  const char* group;
  glsl::vec3 camera, view, sun, extra;  // already rounded to float, as the GPU sees them
  float shadow_length = 0.0f;
};

// Queries in the eval geometry (shaders_runtime/query.h: camera on the z
// axis, so its distance to the centre is exact in float) for every case group.
std::vector<RuntimeQuery> MakeRuntimeQueries(double bottom_radius, double top_radius);

// EvaluateQuery(vec4 camera_what, vec4 view, vec4 sun_shadow, vec4 extra) in
// GLSL: the query's output from its four inputs (RuntimeQueryInputs),
// through the snippet's entry points and the samplers transmittance_texture,
// scattering_texture, single_mie_scattering_texture and irradiance_texture,
// which the shader declares before it. A scene's snippet lacks the functions
// of the tables it left out; their outputs read 0.
extern const char* const kGlslEvaluateQuery;

// The four vec4 inputs of each query, as every test main() reads them:
// camera + what, view ray, sun direction + shadow length, point (aerial) or
// normal (irradiance).
std::vector<std::array<float, 4>> RuntimeQueryInputs(const std::vector<RuntimeQuery>& queries);

// The CPU twin's answer.
glsl::vec3 EvaluateTwin(const LutSet& luts, const RuntimeQuery& query);

// Compares a driver's outputs (one vec4 per query) with the twin's, within
// the tolerances float32 evaluation meets, and prints the largest relative
// differences under `description`.
void ExpectMatchesTwin(const std::string& description, const LutSet& luts, const std::vector<RuntimeQuery>& queries,
                       const std::vector<std::array<float, 4>>& outputs);

// Runs tests/runtime_webgpu/run_wgsl.mjs on the job in `job_dir` (its
// job.json); returns its exit code (77: skipped) with its output in `output`.
int RunWgslJob(const std::filesystem::path& job_dir, std::string* output);

// The same runner's compile-only job: `source` must compile on Dawn into a
// compute pipeline (entry point main). Its exit code (77: skipped) and output.
int CompileWgsl(const std::string& source, std::string* output);

}  // namespace skybake::testing
