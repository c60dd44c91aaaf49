// The runtime a bake ships beside its tables, in each shading language: the
// definitions, a generated constants file, and the functions, to be
// concatenated in that order (GLSL: after the engine's #version line). The
// constants come from the same AtmosphereParameters the manifest records, so
// snippet and tables cannot disagree. The GLSL is the source of every
// function; the HLSL, MSL and WGSL files are its translations
// (shaders_runtime/generated/, written by scripts/translate_runtime.sh).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "shaders_runtime/glsl_shim.h"

namespace skybake {

struct SnippetFile {
  std::string file;  // plain file name
  std::string text;
  std::string description;
};

// The parts of the runtime's functions a bake ships: a scene that leaves out a table
// leaves out the functions that read it (SKYBAKE_HAS_* #defines).
struct SnippetParts {
  bool scattering = true;          // sky radiance (GetSkyRadiance and the 4D lookups)
  bool irradiance = true;          // GetSunAndSkyIrradiance and the irradiance lookups
  bool aerial_perspective = true;  // GetSkyRadianceToPoint[WithShadow]; needs scattering
  // The tables of a spectral bake: every radiance is CIE XYZ (bake/spectral.h),
  // which the constants' comments and SKYBAKE_CHANNELS_ARE_XYZ say.
  bool channels_are_xyz = false;
};

// GLSL (OpenGL 3.3 / ES 3.0, and Vulkan GLSL 4.50), HLSL (Unity, Unreal),
// Metal Shading Language, WGSL (WebGPU).
enum class ShadingLanguage { kGlsl, kHlsl, kMsl, kWgsl };
inline constexpr ShadingLanguage kShadingLanguages[] = {ShadingLanguage::kGlsl, ShadingLanguage::kHlsl,
                                                        ShadingLanguage::kMsl, ShadingLanguage::kWgsl};
// "glsl", "hlsl", "msl", "wgsl"; parsing returns nullopt for anything else.
const char* ShadingLanguageName(ShadingLanguage language);
std::optional<ShadingLanguage> ParseShadingLanguage(std::string_view name);

// `atmosphere_constants.<ext>`: the constant ATMOSPHERE, the wavelengths, and
// the SKYBAKE_HAS_* switches saying which tables and functions exist
// (#defines; WGSL, which has no preprocessor: boolean constants).
std::string AtmosphereConstants(ShadingLanguage language, const glsl::AtmosphereParameters& parameters,
                                const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                const SnippetParts& parts = {});

// The sources of the shipped functions.glsl, in their order of definition:
// scalar primitives, phase functions, ray geometry, the tables' coordinates,
// the sun axis after sunset, the lookups, the sky's entry points, aerial
// perspective and irradiance, and the per-frame tables (sky view and
// aerial-perspective volume).
inline constexpr const char* kRuntimeFunctionSources[] = {
    "primitives.glsl", "phase_functions.glsl", "geometry.glsl",
    "table_mappings.glsl", "shadow_edge.glsl", "lookups.glsl",
    "sky.glsl", "aerial_perspective.glsl", "per_frame.glsl"};

// The shipped functions.glsl: the kRuntimeFunctionSources joined.
std::string RuntimeFunctionsGlsl();

// The shipped files of one language, in the order a shader must include them.
std::vector<SnippetFile> RuntimeSnippetFiles(ShadingLanguage language, const glsl::AtmosphereParameters& parameters,
                                             const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                             const SnippetParts& parts = {});

// The files of RuntimeSnippetFiles joined into one source (no #version line).
std::string RuntimeSnippetSource(ShadingLanguage language, const glsl::AtmosphereParameters& parameters,
                                 const glsl::vec3& wavelengths_nm, const std::string& atmosphere_name,
                                 const SnippetParts& parts = {});

}  // namespace skybake
