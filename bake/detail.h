// The bake's internal namespace, skybake::detail, and the GLSL runtime's C++
// types by the names its files use.
#pragma once

#include "shaders_runtime/runtime.h"

namespace skybake::detail {

using glsl::AtmosphereParameters;
using glsl::Texture;
using glsl::vec3;
using glsl::vec4;

}  // namespace skybake::detail
