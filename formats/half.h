// IEEE 754 binary16 ("half") <-> binary32 conversion, done on bit patterns so
// the result does not depend on the compiler, the FPU rounding mode or F16C.
//
// binary16: 1 sign bit, 5 exponent bits (bias 15), 10 mantissa bits.
// Largest finite value 65504, smallest normal 2^-14, smallest subnormal 2^-24.
//
// FloatToHalf rounds to nearest, ties to even (the IEEE default), produces
// subnormals and signed zeros, overflows to infinity from 65520 upwards (the
// midpoint between 65504 and 2^16 ties to the even pattern, infinity) and
// keeps NaNs NaN (quiet bit forced only where the payload would be lost).
// HalfToFloat is exact: every half value is representable as a float, so
// HalfToFloat followed by FloatToHalf returns every one of the 65536 patterns.
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

inline std::uint16_t FloatToHalf(float value) {
  const std::uint32_t bits = FloatBits(value);
  const std::uint32_t sign = (bits >> 16) & 0x8000u;
  const std::uint32_t magnitude = bits & 0x7FFFFFFFu;

  if (magnitude >= 0x7F800000u) {  // infinity or NaN
    if (magnitude == 0x7F800000u) return static_cast<std::uint16_t>(sign | 0x7C00u);
    // Keep the top 10 payload bits; if they are all zero the value would turn
    // into infinity, so set the quiet bit instead.
    std::uint32_t payload = (magnitude >> 13) & 0x3FFu;
    if (payload == 0) payload = 0x200u;
    return static_cast<std::uint16_t>(sign | 0x7C00u | payload);
  }
  // 65520 = 0x477FF000 is the midpoint between 65504 (odd mantissa 0x3FF) and
  // 2^16 (not representable, i.e. infinity); ties go to even, so it and
  // everything above overflow.
  if (magnitude >= 0x477FF000u) return static_cast<std::uint16_t>(sign | 0x7C00u);

  if (magnitude >= 0x38800000u) {  // >= 2^-14: normal half
    const std::uint32_t exponent = (magnitude >> 23) - 127u + 15u;
    const std::uint32_t mantissa = magnitude & 0x7FFFFFu;
    std::uint32_t half = (exponent << 10) | (mantissa >> 13);
    const std::uint32_t rest = mantissa & 0x1FFFu;  // the 13 dropped bits
    // A carry out of the mantissa correctly increments the exponent (and can
    // reach 0x7C00 only for inputs already handled as overflow above).
    if (rest > 0x1000u || (rest == 0x1000u && (half & 1u))) ++half;
    return static_cast<std::uint16_t>(sign | half);
  }

  // Subnormal half (or zero): value = h * 2^-24. Inputs up to 2^-25 (the
  // midpoint between 0 and 2^-24) round to an even zero.
  if (magnitude <= 0x33000000u) return static_cast<std::uint16_t>(sign);
  const std::uint32_t biased_exponent = magnitude >> 23;  // 102..112 here
  const std::uint32_t mantissa = (magnitude & 0x7FFFFFu) | 0x800000u;
  // value = mantissa * 2^(biased_exponent - 150), so h = mantissa >> shift.
  const std::uint32_t shift = 126u - biased_exponent;  // 14..24
  std::uint32_t half = mantissa >> shift;
  const std::uint32_t rest = mantissa & ((1u << shift) - 1u);
  const std::uint32_t midpoint = 1u << (shift - 1u);
  // Rounding 0x3FF up yields 0x400, the smallest normal: also correct.
  if (rest > midpoint || (rest == midpoint && (half & 1u))) ++half;
  return static_cast<std::uint16_t>(sign | half);
}

inline float HalfToFloat(std::uint16_t half) {
  const std::uint32_t sign = static_cast<std::uint32_t>(half & 0x8000u) << 16;
  const std::uint32_t exponent = (half >> 10) & 0x1Fu;
  std::uint32_t mantissa = half & 0x3FFu;

  if (exponent == 0x1Fu) return FloatFromBits(sign | 0x7F800000u | (mantissa << 13));
  if (exponent != 0) return FloatFromBits(sign | ((exponent + 127u - 15u) << 23) | (mantissa << 13));
  if (mantissa == 0) return FloatFromBits(sign);
  // Subnormal half: normalise into a float, which has exponent range to spare.
  std::uint32_t float_exponent = 127u - 14u;  // exponent of 2^-14
  while ((mantissa & 0x400u) == 0) {
    mantissa <<= 1;
    --float_exponent;
  }
  return FloatFromBits(sign | (float_exponent << 23) | ((mantissa & 0x3FFu) << 13));
}

}  // namespace skybake
