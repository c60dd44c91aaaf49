// The GLSL snippet a bake ships beside its tables: definitions.glsl, a
// generated constants file, and functions.glsl, to be concatenated in that
// order after the engine's #version line. The constants come from the same
// AtmosphereParameters the manifest records, so snippet and tables cannot
// disagree.
#pragma once

#include <string>
#include <vector>

#include "shaders_runtime/glsl_shim.h"

namespace skybake {

struct SnippetFile {
  std::string file;  // plain file name
  std::string text;
  std::string description;
};

// The parts of functions.glsl a bake ships: a scene that leaves out a table
// leaves out the functions that read it (SKYBAKE_HAS_* #defines).
struct SnippetParts {
  bool scattering = true;          // sky radiance (GetSkyRadiance and the 4D lookups)
  bool irradiance = true;          // GetSunAndSkyIrradiance and the irradiance lookups
  bool aerial_perspective = true;  // GetSkyRadianceToPoint[WithShadow]; needs scattering
};

// `atmosphere_constants.glsl`: `const AtmosphereParameters ATMOSPHERE`, the
// wavelengths, and #defines saying which tables and functions exist.
std::string AtmosphereConstantsGlsl(const glsl::AtmosphereParameters& parameters, const glsl::vec3& wavelengths_nm,
                                    const std::string& atmosphere_name, const SnippetParts& parts = {});

// The sources of the shipped functions.glsl, in their order of definition:
// scalar primitives, phase functions, geometry, parameterization, lookups and
// sky radiance, then aerial perspective and irradiance.
inline constexpr const char* kRuntimeFunctionSources[] = {"primitives.glsl", "phase_functions.glsl",
                                                           "functions.glsl", "aerial_perspective.glsl"};

// The shipped functions.glsl: the kRuntimeFunctionSources joined.
std::string RuntimeFunctionsGlsl();

// The shipped files, in the order a shader must include them.
std::vector<SnippetFile> RuntimeSnippetFiles(const glsl::AtmosphereParameters& parameters,
                                             const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                             const SnippetParts& parts = {});

// The files of RuntimeSnippetFiles joined into one source (no #version line).
std::string RuntimeSnippetSource(const glsl::AtmosphereParameters& parameters, const glsl::vec3& wavelengths_nm,
                                 const std::string& atmosphere_name, const SnippetParts& parts = {});

}  // namespace skybake
