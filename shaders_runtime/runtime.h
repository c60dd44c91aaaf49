// The GLSL runtime compiled as C++ (double precision): every function of
// primitives.glsl and phase_functions.glsl (primitives.h), the sources of
// functions.glsl (kRuntimeFunctionSources, shaders_runtime/snippet.h),
// aerial_perspective.glsl, per_frame.glsl and inverse_parameterization.glsl,
// in namespace skybake::glsl. The bake uses the parameterization and lookups; the CPU twin
// (twin.h) uses the run-time functions. Each translation unit gets its own
// internal copy, as GLSL functions cannot be declared inline.
#pragma once

#include "shaders_runtime/glsl_shim.h"
#include "shaders_runtime/primitives.h"

#define IN(type) const type&
#define OUT(type) type&
#define TransmittanceTexture sampler2D
#define ScatteringTexture sampler3D
#define IrradianceTexture sampler2D
#define SkyViewTexture sampler2D
#define AerialPerspectiveTexture sampler3D
#define SampleTexture2D texture
#define SampleTexture3D texture

namespace skybake::glsl {
namespace {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include "shaders_runtime/geometry.glsl"
#include "shaders_runtime/table_mappings.glsl"
#include "shaders_runtime/shadow_edge.glsl"
#include "shaders_runtime/lookups.glsl"
#include "shaders_runtime/sky.glsl"
#include "shaders_runtime/aerial_perspective.glsl"
#include "shaders_runtime/per_frame.glsl"
#include "shaders_runtime/inverse_parameterization.glsl"
#pragma GCC diagnostic pop
}  // namespace
}  // namespace skybake::glsl

#undef IN
#undef OUT
#undef TransmittanceTexture
#undef ScatteringTexture
#undef IrradianceTexture
#undef SkyViewTexture
#undef AerialPerspectiveTexture
#undef SampleTexture2D
#undef SampleTexture3D
