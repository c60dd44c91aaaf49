// Float functions for the bake's vectorised inner loops: inline and free of
// library calls, so that a loop over a ray's texels that uses them compiles
// to SIMD instructions. Tested against the standard library in
// tests/float_math_test.cpp.
#pragma once

#include <cstdint>

namespace skybake {

// Floats in the widest SIMD vector the bake's loops use (512 bits). A loop
// that starts at a multiple of it puts each element in the lane it has when
// the loop starts at 0, and so computes it the same way to the bit.
constexpr int kVectorFloats = 16;

// x clamped to [lo, hi], by value (std::clamp returns a reference, which
// can keep a loop from vectorising).
inline float ClampFloat(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }

// exp(x) within 2 float ulps for x in [-87, 88]; below -87 it returns
// ~1.6e-38 instead of a denormal or 0 (a transmittance that small scales
// nothing the tables can hold), above 88 the value at 88.
inline float ExpFloat(float x) {
  x = x < -87.0f ? -87.0f : (x > 88.0f ? 88.0f : x);
  // x = k ln2 + f with |f| <= ln2 / 2; ln2 split in two so that k ln2 is
  // exact. k is rounded by adding and subtracting 1.5 * 2^23 (floorf does
  // not vectorise while floating-point exceptions are honoured).
  const float round = 12582912.0f;
  const float k = (x * 1.44269504f + round) - round;
  const float f = (x - k * 0.693359375f) - k * -2.12194440e-4f;
  // Minimax polynomial for exp on [-ln2 / 2, ln2 / 2] (Cephes expf).
  float p = 1.9875691500e-4f;
  p = p * f + 1.3981999507e-3f;
  p = p * f + 8.3334519073e-3f;
  p = p * f + 4.1665795894e-2f;
  p = p * f + 1.6666665459e-1f;
  p = p * f + 5.0000001201e-1f;
  p = p * f * f + f + 1.0f;
  // 2^k from its exponent bits (a bit cast rather than memcpy keeps the
  // loop vectorisable).
  const float scale = __builtin_bit_cast(float, (static_cast<std::int32_t>(k) + 127) << 23);
  return p * scale;
}

// (exp(lambda) - 1) / lambda, the integral over [0, 1] of exp(lambda s),
// for |lambda| <= 0.1 (its Taylor series to lambda^4, error below 1.5e-8).
inline float ExpRampSmall(float lambda) {
  return 1.0f + lambda * (0.5f + lambda * (1.0f / 6.0f + lambda * (1.0f / 24.0f + lambda * (1.0f / 120.0f))));
}

// Integral over an interval of width h of a positive function taking the
// values a and b at its ends and exponential in between, with lambda =
// ln(b / a) given by the caller (from logarithms, so that an end that
// underflowed to 0 still decays at its true rate): h (b - a) / lambda, by
// its series where lambda is small (the difference would cancel); never
// negative (a and b rounded apart from lambda could make it so).
inline float ExponentialTrapezoidFloat(float a, float b, float lambda, float h) {
  const bool small = lambda > -0.1f && lambda < 0.1f;
  const float integral = small ? h * a * ExpRampSmall(lambda) : h * (b - a) / lambda;
  return integral > 0.0f ? integral : 0.0f;
}

}  // namespace skybake
