// Zstandard-supercompressed KTX2 (formats/ktx2.h): the layout the KTX 2.0
// specification gives a deflated level (scheme 2 in the header, the level
// right after the key/value data with no mipPadding, byteLength the stored
// and uncompressedByteLength the inflated size, RFC 8478 frames), a bit-exact
// round trip, and one-line IoErrors for damaged or implausible levels.
#include <gtest/gtest.h>

#include <string>

#include "formats/ktx2.h"
#include "ktx2_test_util.h"

namespace skybake::ktx2 {
namespace {

constexpr std::size_t kLevelIndex = 80;  // levels[0] after the 80-byte header

Texture Zstd(Texture t, int level = kZstdDefaultLevel) {
  t.supercompression = Supercompression::kZstd;
  t.zstd_level = level;
  return t;
}

TEST(Ktx2Zstd, LayoutFollowsTheSpecification) {
  for (VkFormat format : kAllFormats) {
    for (std::uint32_t depth : {0u, 3u}) {
      SCOPED_TRACE(std::string(FormatName(format)) + " depth " + std::to_string(depth));
      const Texture t = Zstd(MakeTexture(format, 17, 5, depth, {{"skybake.x", "abc"}}));
      const Bytes file = Encode(t);
      EXPECT_EQ(U32(file, 44), 2u);  // supercompressionScheme: Zstandard
      EXPECT_EQ(U32(file, 12), static_cast<std::uint32_t>(format));  // vkFormat kept
      const std::uint64_t offset = U64(file, kLevelIndex), length = U64(file, kLevelIndex + 8);
      EXPECT_EQ(U64(file, kLevelIndex + 16), t.data.size());  // uncompressedByteLength
      EXPECT_EQ(offset, U32(file, 56) + U32(file, 60));       // right after the key/value data
      EXPECT_EQ(offset + length, file.size());
      // RFC 8478 section 3.1.1: a frame starts with the magic 0xFD2FB528.
      EXPECT_EQ(U32(file, offset), 0xFD2FB528u);
      const Texture back = Decode(file, "zstd.ktx2");
      EXPECT_EQ(back.supercompression, Supercompression::kZstd);
      EXPECT_EQ(back.data, t.data);
      EXPECT_EQ(back.key_values.at("skybake.x"), "abc");
    }
  }
}

TEST(Ktx2Zstd, EveryLevelRoundTripsAndRepetitiveDataShrinks) {
  const Texture t = MakeTexture(VkFormat::kR32G32B32A32Sfloat, 64, 32, 4);
  for (int level : {kZstdMinLevel, kZstdDefaultLevel, 9, kZstdMaxLevel}) {
    const Bytes file = Encode(Zstd(t, level));
    EXPECT_EQ(Decode(file, "zstd.ktx2").data, t.data) << level;
    EXPECT_LT(file.size(), t.data.size() / 4) << level;  // 1000 distinct values repeated
  }
  EXPECT_THROW(Encode(Zstd(t, 0)), InternalError);
  EXPECT_THROW(Encode(Zstd(t, 23)), InternalError);
}

TEST(Ktx2Zstd, DamagedLevelsAreOneLineIoErrors) {
  const Bytes good = Encode(Zstd(MakeTexture(VkFormat::kR16G16B16A16Sfloat, 32, 8, 2)));
  const std::uint64_t offset = U64(good, kLevelIndex), length = U64(good, kLevelIndex + 8);
  const std::uint64_t inflated = U64(good, kLevelIndex + 16);

  Bytes bad_magic = good;
  bad_magic[offset] ^= 0xFF;
  EXPECT_NE(DecodeError(bad_magic).find("corrupt level data: zstd"), std::string::npos) << DecodeError(bad_magic);

  // Inflating to less, or to more, than uncompressedByteLength says.
  // (A header change that keeps the index consistent: 32 x 8 x 1 instead of
  // 32 x 8 x 2, so the frame declares more than the index.)
  Bytes claims_less = good;
  SetU32(claims_less, 28, 1);
  SetU64(claims_less, kLevelIndex + 16, inflated / 2);
  EXPECT_NE(DecodeError(claims_less).find("its zstd frame declares " + std::to_string(inflated)), std::string::npos)
      << DecodeError(claims_less);
  Bytes cut_level = Slice(good, 0, offset + length - 1);
  SetU64(cut_level, kLevelIndex + 8, length - 1);
  EXPECT_NE(DecodeError(cut_level).find("corrupt level data"), std::string::npos) << DecodeError(cut_level);

  // A level that claims to inflate to more than skybake reads is refused
  // before anything is allocated for it (1024 x 1024 x 512 RGBA half: 4 GiB);
  // one whose frames hold less is corrupt (1024 x 1024 x 16: 128 MiB).
  Bytes huge = good;
  SetU32(huge, 20, 1024), SetU32(huge, 24, 1024), SetU32(huge, 28, 512);
  SetU64(huge, kLevelIndex + 16, std::uint64_t(1024) * 1024 * 512 * 8);
  EXPECT_NE(DecodeError(huge).find("unsupported KTX2 file: level of 4294967296 bytes after inflation"),
            std::string::npos)
      << DecodeError(huge);
  SetU32(huge, 28, 16);
  SetU64(huge, kLevelIndex + 16, std::uint64_t(1024) * 1024 * 16 * 8);
  EXPECT_NE(DecodeError(huge).find("inflates to 4096 bytes"), std::string::npos) << DecodeError(huge);

  // BasisLZ (scheme 1) is outside skybake's scope.
  Bytes basis = good;
  SetU32(basis, 44, 1);
  EXPECT_NE(DecodeError(basis).find("unsupported KTX2 file: supercompressionScheme 1"), std::string::npos);

  // Every single flipped bit: decoded or refused with an IoError, never a crash.
  for (std::size_t at = 0; at < good.size(); ++at) {
    Bytes flipped = good;
    flipped[at] ^= static_cast<std::uint8_t>(1u << (at % 8));
    DecodeError(flipped);
  }
}

}  // namespace
}  // namespace skybake::ktx2
