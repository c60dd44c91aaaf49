// Imath::half, with which every half table is written, against the IEEE 754
// binary16 definition: every one of the 65536 patterns, every rounding
// boundary between adjacent halves (round to nearest, ties to even), and
// hand-checked values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include <Imath/half.h>

#include "core/float_bits.h"

namespace skybake {
namespace {

// The conversions under test, on bit patterns.
std::uint16_t FloatToHalf(float value) { return Imath::half(value).bits(); }
float HalfToFloat(std::uint16_t bits) { return Imath::half(Imath::half::FromBits, bits); }

bool IsHalfNan(std::uint16_t h) { return (h & 0x7C00u) == 0x7C00u && (h & 0x3FFu) != 0; }

// The value a binary16 pattern denotes, straight from the definition:
// (-1)^s * 2^(e-15) * (1 + m/1024) for 0 < e < 31, (-1)^s * 2^-14 * m/1024 for e = 0.
double HalfValueByDefinition(std::uint16_t h) {
  const int sign = (h & 0x8000u) ? -1 : 1;
  const int e = (h >> 10) & 0x1F;
  const int m = h & 0x3FF;
  if (e == 0x1F) return sign * std::numeric_limits<double>::infinity();
  if (e == 0) return sign * std::ldexp(static_cast<double>(m), -24);
  return sign * std::ldexp(static_cast<double>(1024 + m), e - 25);
}

TEST(Half, EveryPatternSurvivesHalfToFloatToHalf) {
  for (std::uint32_t h = 0; h <= 0xFFFFu; ++h) {
    const auto half = static_cast<std::uint16_t>(h);
    const float f = HalfToFloat(half);
    ASSERT_EQ(FloatToHalf(f), half) << "pattern 0x" << std::hex << h;
    ASSERT_EQ(std::isnan(f), IsHalfNan(half)) << "pattern 0x" << std::hex << h;
  }
}

TEST(Half, HalfToFloatMatchesTheDefinitionForEveryPattern) {
  for (std::uint32_t h = 0; h <= 0xFFFFu; ++h) {
    const auto half = static_cast<std::uint16_t>(h);
    if (IsHalfNan(half)) continue;
    const float f = HalfToFloat(half);
    ASSERT_EQ(static_cast<double>(f), HalfValueByDefinition(half)) << "pattern 0x" << std::hex << h;
    ASSERT_EQ(std::signbit(f), (h & 0x8000u) != 0) << "pattern 0x" << std::hex << h;
  }
}

TEST(Half, KnownHalfValues) {
  EXPECT_EQ(HalfToFloat(0x3C00), 1.0f);
  EXPECT_EQ(HalfToFloat(0xC000), -2.0f);
  EXPECT_EQ(HalfToFloat(0x7BFF), 65504.0f);           // largest finite
  EXPECT_EQ(HalfToFloat(0x0400), std::ldexp(1.0f, -14));  // smallest normal
  EXPECT_EQ(HalfToFloat(0x03FF), std::ldexp(1023.0f, -24));  // largest subnormal
  EXPECT_EQ(HalfToFloat(0x0001), std::ldexp(1.0f, -24));  // smallest subnormal
  EXPECT_EQ(HalfToFloat(0x3555), 0.333251953125f);    // nearest half to 1/3
  EXPECT_EQ(FloatBits(HalfToFloat(0x8000)), 0x80000000u);  // -0
  EXPECT_EQ(HalfToFloat(0x7C00), std::numeric_limits<float>::infinity());
  EXPECT_EQ(HalfToFloat(0xFC00), -std::numeric_limits<float>::infinity());
  EXPECT_TRUE(std::isnan(HalfToFloat(0x7E00)));
}

TEST(Half, KnownFloatToHalfRoundings) {
  EXPECT_EQ(FloatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(FloatToHalf(-2.0f), 0xC000);
  EXPECT_EQ(FloatToHalf(0.1f), 0x2E66);   // 0.0999755859375; 0x2E67 is farther
  EXPECT_EQ(FloatToHalf(1.0f / 3.0f), 0x3555);
  EXPECT_EQ(FloatToHalf(0.0f), 0x0000);
  EXPECT_EQ(FloatToHalf(-0.0f), 0x8000);
  // Ties to even in the normal range: 1 + 2^-11 lies halfway between 0x3C00
  // and 0x3C01, 1 + 3*2^-11 halfway between 0x3C01 and 0x3C02.
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11)), 0x3C00);
  EXPECT_EQ(FloatToHalf(1.0f + 3.0f * std::ldexp(1.0f, -11)), 0x3C02);
  EXPECT_EQ(FloatToHalf(1.0f + std::ldexp(1.0f, -11) + std::ldexp(1.0f, -23)), 0x3C01);
  // Overflow: 65504 is the largest half; 65520 ties between 65504 (odd) and
  // 2^16 (even, infinity), so it and everything above become infinity.
  EXPECT_EQ(FloatToHalf(65504.0f), 0x7BFF);
  EXPECT_EQ(FloatToHalf(std::nextafter(65520.0f, 0.0f)), 0x7BFF);
  EXPECT_EQ(FloatToHalf(65520.0f), 0x7C00);
  EXPECT_EQ(FloatToHalf(-65520.0f), 0xFC00);
  EXPECT_EQ(FloatToHalf(1e30f), 0x7C00);
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::max()), 0x7C00);
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::infinity()), 0x7C00);
  EXPECT_EQ(FloatToHalf(-std::numeric_limits<float>::infinity()), 0xFC00);
  // Subnormals: 2^-25 ties between 0 and 2^-24 (to the even zero); 1.5 and
  // 2.5 times 2^-24 both tie to 2 * 2^-24.
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -24)), 0x0001);
  EXPECT_EQ(FloatToHalf(std::ldexp(1.0f, -25)), 0x0000);
  EXPECT_EQ(FloatToHalf(-std::ldexp(1.0f, -25)), 0x8000);
  EXPECT_EQ(FloatToHalf(std::nextafter(std::ldexp(1.0f, -25), 1.0f)), 0x0001);
  EXPECT_EQ(FloatToHalf(1.5f * std::ldexp(1.0f, -24)), 0x0002);
  EXPECT_EQ(FloatToHalf(2.5f * std::ldexp(1.0f, -24)), 0x0002);
  EXPECT_EQ(FloatToHalf(std::numeric_limits<float>::denorm_min()), 0x0000);
  EXPECT_EQ(FloatToHalf(1e-10f), 0x0000);
  // Just below the smallest normal rounds up into it.
  EXPECT_EQ(FloatToHalf(std::nextafter(std::ldexp(1.0f, -14), 0.0f)), 0x0400);
  EXPECT_EQ(FloatToHalf(std::ldexp(1023.0f, -24)), 0x03FF);
}

TEST(Half, NanStaysNan) {
  EXPECT_TRUE(IsHalfNan(FloatToHalf(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_TRUE(IsHalfNan(FloatToHalf(-std::numeric_limits<float>::quiet_NaN())));
  // Payload only in the 13 bits a half cannot hold: must not become infinity.
  EXPECT_TRUE(IsHalfNan(FloatToHalf(FloatFromBits(0x7F800001u))));
  EXPECT_TRUE(IsHalfNan(FloatToHalf(FloatFromBits(0xFF801000u))));
  EXPECT_EQ(FloatToHalf(FloatFromBits(0xFF801000u)) & 0x8000u, 0x8000u);
}

// Every boundary between two adjacent finite halves of either sign: the
// float midpoint (exact, since halves have 11 significant bits and floats 24)
// goes to the even neighbour, and the floats on either side of it go to the
// nearer neighbour.
TEST(Half, EveryRoundingBoundaryBetweenAdjacentHalves) {
  for (std::uint32_t h = 0; h < 0x7BFFu; ++h) {
    const auto lo_half = static_cast<std::uint16_t>(h);
    const auto hi_half = static_cast<std::uint16_t>(h + 1);
    const double lo = HalfValueByDefinition(lo_half);
    const double hi = HalfValueByDefinition(hi_half);
    const float mid = static_cast<float>((lo + hi) / 2);
    ASSERT_EQ(static_cast<double>(mid), (lo + hi) / 2) << "midpoint not exact at 0x" << std::hex << h;
    const std::uint16_t even = (h % 2 == 0) ? lo_half : hi_half;
    for (int sign = 0; sign < 2; ++sign) {
      const float s = sign ? -1.0f : 1.0f;
      const std::uint16_t sign_bit = sign ? 0x8000 : 0;
      ASSERT_EQ(FloatToHalf(s * mid), even | sign_bit) << "tie at 0x" << std::hex << h;
      ASSERT_EQ(FloatToHalf(s * std::nextafter(mid, 0.0f)), lo_half | sign_bit) << "below tie at 0x" << std::hex << h;
      ASSERT_EQ(FloatToHalf(s * std::nextafter(mid, 1e9f)), hi_half | sign_bit) << "above tie at 0x" << std::hex << h;
      ASSERT_EQ(FloatToHalf(s * static_cast<float>(lo)), lo_half | sign_bit);
    }
  }
}

}  // namespace
}  // namespace skybake
