// Generated code for the fitted surfaces: one GLSL function per constituent
// (sky_dome_fit.glsl) and its C++ twin (sky_dome_fit.h), produced from the
// same function text so the two cannot drift apart:
//
//   float skybake_relative_optical_path_<identifier>(float mu, float altitude_m)
//
// returns m = slant column / vertical column for a view ray with cosine of
// the zenith angle `mu` from an observer at `altitude_m` above the ground;
// mu is clamped to [0, 1] (rays below the horizon get the horizon value) and
// the altitude to the fitted range. The text is the GLSL subset that is also
// C++: float arithmetic, f-suffixed literals, and the built-ins exp, sqrt,
// pow, clamp, which the C++ preamble defines in float.
//
// The GLSL file has no #version line and is valid GLSL 3.30 core and GLSL ES
// 3.00; ES fragment shaders need `precision highp float;` before it (the
// default in vertex shaders).
#pragma once

#include <string>

#include "fit/sky_dome_fit.h"

namespace skybake::fit {

// `provenance` is a one-line description (command line and version) put in
// the header comment of both files.
std::string GenerateGlsl(const FitSet& set, const std::string& provenance);
std::string GenerateCppTwin(const FitSet& set, const std::string& provenance);

// The function name for one constituent.
std::string FunctionName(const ConstituentFit& fit);

}  // namespace skybake::fit
