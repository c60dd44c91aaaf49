// Mathematical constants shared by every part of skybake.
#pragma once

namespace skybake {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace skybake
