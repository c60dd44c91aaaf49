// primitives.glsl and phase_functions.glsl compiled as C++ twice: in double
// precision in namespace skybake::glsl (with the rest of the runtime, see
// runtime.h), and in float in namespace skybake::glsl_float for the bake's
// vectorised loops. The float shim below gives the built-ins those files use,
// by value and free of library calls other than sqrt, so that a loop calling
// them still compiles to SIMD instructions. tests/runtime_float_test.cpp
// compares every float function with its double original.
#pragma once

#include <cmath>

#include "core/constants.h"
#include "shaders_runtime/glsl_shim.h"

namespace skybake::glsl {
namespace {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include "shaders_runtime/primitives.glsl"
#include "shaders_runtime/phase_functions.glsl"
#pragma GCC diagnostic pop
}  // namespace
}  // namespace skybake::glsl

namespace skybake::glsl_float {

using Number = float;
constexpr Number PI = Number(kPi);

inline Number max(Number a, Number b) { return a < b ? b : a; }
inline Number min(Number a, Number b) { return b < a ? b : a; }
inline Number clamp(Number x, Number lo, Number hi) { return min(max(x, lo), hi); }
inline Number sqrt(Number x) { return std::sqrt(x); }
// GLSL's smoothstep (edge0 < edge1).
inline Number smoothstep(Number edge0, Number edge1, Number x) {
  Number t = clamp((x - edge0) / (edge1 - edge0), Number(0.0), Number(1.0));
  return t * t * (Number(3.0) - Number(2.0) * t);
}

namespace {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include "shaders_runtime/primitives.glsl"
#include "shaders_runtime/phase_functions.glsl"
#pragma GCC diagnostic pop
}  // namespace

}  // namespace skybake::glsl_float
