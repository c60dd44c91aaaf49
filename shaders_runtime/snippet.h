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

// `atmosphere_constants.glsl`: `const AtmosphereParameters ATMOSPHERE`, the
// wavelengths, and #defines saying which tables exist.
std::string AtmosphereConstantsGlsl(const glsl::AtmosphereParameters& parameters, const glsl::vec3& wavelengths_nm,
                                    const std::string& atmosphere_name);

// The shipped files, in the order a shader must include them.
std::vector<SnippetFile> RuntimeSnippetFiles(const glsl::AtmosphereParameters& parameters,
                                             const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name);

// The files of RuntimeSnippetFiles joined into one source (no #version line).
std::string RuntimeSnippetSource(const glsl::AtmosphereParameters& parameters, const glsl::vec3& wavelengths_nm,
                                 const std::string& atmosphere_name);

}  // namespace skybake
