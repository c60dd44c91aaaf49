// A float's IEEE-754 bit pattern and back (the file formats write floats as
// words; tests build NaNs and signed zeros from their bits).
#pragma once

#include <cstdint>
#include <cstring>

namespace skybake {

inline std::uint32_t FloatBits(float value) {
  std::uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

inline float FloatFromBits(std::uint32_t bits) {
  float value;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

}  // namespace skybake
