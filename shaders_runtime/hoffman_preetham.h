// Hoffman & Preetham's analytic model (hoffman_preetham.glsl) compiled as C++
// in double precision, in namespace skybake::glsl. A separate header from
// runtime.h: the model shares only the phase functions with the sky runtime
// (phase_functions.glsl, through primitives.h), and a translation unit may
// include both. As with runtime.h, each translation unit
// gets its own internal copy (GLSL functions cannot be declared inline), so
// keep HoffmanPreethamParameters out of headers that other units include.
#pragma once

#include "shaders_runtime/glsl_shim.h"
#include "shaders_runtime/primitives.h"

#define IN(type) const type&
#define OUT(type) type&

namespace skybake::glsl {
namespace {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include "shaders_runtime/hoffman_preetham.glsl"
#pragma GCC diagnostic pop
}  // namespace
}  // namespace skybake::glsl

#undef IN
#undef OUT
