// KTX2 writer/reader tests. Expected bytes and offsets are derived by hand
// from the KTX 2.0 specification (section numbers in comments) and the
// Khronos Data Format Specification 1.4 (KDF), not taken from Encode's output.
// Decoding damaged files and the cross-check sample set: ktx2_decode_test.cpp.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/file_io.h"
#include "core/version.h"
#include "formats/ktx2.h"
#include "ktx2_test_util.h"

namespace skybake::ktx2 {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// Formats

TEST(Ktx2Format, VkFormatValuesFromTheVulkanSpecification) {
  EXPECT_EQ(static_cast<std::uint32_t>(VkFormat::kR16Sfloat), 76u);
  EXPECT_EQ(static_cast<std::uint32_t>(VkFormat::kR16G16B16A16Sfloat), 97u);
  EXPECT_EQ(static_cast<std::uint32_t>(VkFormat::kR32Sfloat), 100u);
  EXPECT_EQ(static_cast<std::uint32_t>(VkFormat::kR32G32B32A32Sfloat), 109u);
  EXPECT_EQ(BytesPerTexel(VkFormat::kR16Sfloat), 2u);
  EXPECT_EQ(BytesPerTexel(VkFormat::kR32Sfloat), 4u);
  EXPECT_EQ(BytesPerTexel(VkFormat::kR16G16B16A16Sfloat), 8u);
  EXPECT_EQ(BytesPerTexel(VkFormat::kR32G32B32A32Sfloat), 16u);
  EXPECT_EQ(ChannelCount(VkFormat::kR16Sfloat), 1);
  EXPECT_EQ(ChannelCount(VkFormat::kR32G32B32A32Sfloat), 4);
  EXPECT_FALSE(IsSupportedFormat(37));  // VK_FORMAT_R8G8B8A8_UNORM
}

TEST(Ktx2Format, PackFloatsIsLittleEndianAndRoundsHalves) {
  const Bytes f32 = PackFloats(VkFormat::kR32Sfloat, {1.0f});
  EXPECT_EQ(f32, (Bytes{0x00, 0x00, 0x80, 0x3F}));
  const Bytes f16 = PackFloats(VkFormat::kR16Sfloat, {1.0f, -2.0f, 0.1f});
  EXPECT_EQ(f16, (Bytes{0x00, 0x3C, 0x00, 0xC0, 0x66, 0x2E}));
  const auto back = UnpackFloats(VkFormat::kR16Sfloat, f16);
  EXPECT_EQ(back[0], 1.0f);
  EXPECT_EQ(back[1], -2.0f);
  EXPECT_EQ(back[2], static_cast<float>(Imath::half(Imath::half::FromBits, 0x2E66)));
}

// ---------------------------------------------------------------------------
// Layout, hand-derived from the specification

// A 2x2 VK_FORMAT_R32G32B32A32_SFLOAT 2D texture with KTXwriter "skybake test".
//  §2: 12 identifier bytes, then nine UInt32 header fields (12..47), then the
//  index: dfdByteOffset @48, dfdByteLength @52, kvdByteOffset @56,
//  kvdByteLength @60, sgdByteOffset (UInt64) @64, sgdByteLength @72, then
//  levels[1] of three UInt64 @80..103, so the DFD starts at 104.
//  DFD (KDF §4, §5): 4 (dfdTotalSize) + 24 + 16 * 4 samples = 92 bytes -> 196.
//  KVD (§3.11) at 196, keys sorted by code point ('o' < 'w'):
//    "KTXorientation\0rd\0" = 18 bytes: 4 + 18 + 2 padding = 24 -> 220
//    "KTXwriter\0skybake test\0" = 23 bytes: 4 + 23 + 1 padding = 28 -> 248
//    kvdByteLength = 52.
//  Level (§3.13.2): aligned to lcm(16, 4) = 16 -> 256 (8 bytes of mipPadding),
//  2 * 2 * 16 = 64 bytes -> file size 320.
TEST(Ktx2Layout, HeaderIndexAndLevelOffsetsFollowTheSpecification) {
  const Texture t = MakeTexture(VkFormat::kR32G32B32A32Sfloat, 2, 2, 0, {{"KTXwriter", "skybake test"}});
  const Bytes f = Encode(t);
  ASSERT_EQ(f.size(), 320u);
  // §3.1 identifier: « K T X space 2 0 » CR LF SUB LF.
  EXPECT_EQ(Slice(f, 0, 12), (Bytes{0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A}));
  EXPECT_EQ(U32(f, 12), 109u);  // vkFormat = VK_FORMAT_R32G32B32A32_SFLOAT
  EXPECT_EQ(U32(f, 16), 4u);    // typeSize: bytes of one component (§3.3)
  EXPECT_EQ(U32(f, 20), 2u);    // pixelWidth
  EXPECT_EQ(U32(f, 24), 2u);    // pixelHeight
  EXPECT_EQ(U32(f, 28), 0u);    // pixelDepth: 0 for 2D (§4.1)
  EXPECT_EQ(U32(f, 32), 0u);    // layerCount: not an array (§3.5)
  EXPECT_EQ(U32(f, 36), 1u);    // faceCount: not a cubemap (§3.6)
  EXPECT_EQ(U32(f, 40), 1u);    // levelCount: base level only, no mipmaps wanted (§3.7)
  EXPECT_EQ(U32(f, 44), 0u);    // supercompressionScheme: none (§3.8)
  EXPECT_EQ(U32(f, 48), 104u);  // dfdByteOffset
  EXPECT_EQ(U32(f, 52), 92u);   // dfdByteLength
  EXPECT_EQ(U32(f, 56), 196u);  // kvdByteOffset
  EXPECT_EQ(U32(f, 60), 52u);   // kvdByteLength
  EXPECT_EQ(U64(f, 64), 0u);    // sgdByteOffset: 0 when sgdByteLength is 0 (§3.9.5)
  EXPECT_EQ(U64(f, 72), 0u);    // sgdByteLength
  EXPECT_EQ(U64(f, 80), 256u);  // levels[0].byteOffset
  EXPECT_EQ(U64(f, 88), 64u);   // levels[0].byteLength
  EXPECT_EQ(U64(f, 96), 64u);   // levels[0].uncompressedByteLength = byteLength without supercompression
  EXPECT_EQ(U32(f, 104), 92u);  // dfdTotalSize = dfdByteLength (§3.9.2)
  EXPECT_EQ(Slice(f, 196, 52),
            Ascii(std::string("\x12\0\0\0KTXorientation\0rd\0\0\0", 24) +
                  std::string("\x17\0\0\0KTXwriter\0skybake test\0\0", 28)));
  EXPECT_EQ(Slice(f, 248, 8), Bytes(8, 0));  // mipPadding
  EXPECT_EQ(Slice(f, 256, 64), t.data);
}

// Expected DFDs (dfdTotalSize included), one 32-bit little-endian word per
// line, from KDF §5 "Khronos Basic Data Format Descriptor Block":
//  word 1: vendorId 0 (bits 0-16) | descriptorType 0 (bits 17-31)
//  word 2: versionNumber 2 (bits 0-15) | descriptorBlockSize 24 + 16 * samples (bits 16-31)
//  word 3: colorModel RGBSDA 1 | colorPrimaries BT709 1 << 8 | transferFunction
//          LINEAR 1 << 16 | flags ALPHA_STRAIGHT 0 << 24 = 0x00010101
//  word 4: texelBlockDimension0..3, each stored as size - 1: 1x1x1x1 -> 0
//  word 5: bytesPlane0 = texel size, bytesPlane1..3 = 0; word 6: bytesPlane4..7 = 0
//  per sample (KDF §5.12-§5.17), one per channel in memory order:
//   bitOffset (bits 0-15) | bitLength - 1 (bits 16-23) | channelType (bits 24-27:
//   R 0, G 1, B 2, A 15) | qualifiers (bits 28-31: FLOAT 0x80 | SIGNED 0x40)
//   samplePosition0..3 = 0
//   sampleLower = -1.0f = 0xBF800000, sampleUpper = 1.0f = 0x3F800000: floats
//   for float channels, the -1..1 range of a signed channel (KDF §5.17).
const Bytes kDfdR16 = {
    0x2C, 0x00, 0x00, 0x00,  // dfdTotalSize 44 = 4 + 24 + 16
    0x00, 0x00, 0x00, 0x00,  // vendorId 0, descriptorType 0
    0x02, 0x00, 0x28, 0x00,  // versionNumber 2, descriptorBlockSize 40
    0x01, 0x01, 0x01, 0x00,  // RGBSDA, BT709, LINEAR, straight alpha
    0x00, 0x00, 0x00, 0x00,  // texelBlockDimension 1x1x1x1
    0x02, 0x00, 0x00, 0x00,  // bytesPlane0 2
    0x00, 0x00, 0x00, 0x00,  // bytesPlane4..7
    0x00, 0x00, 0x0F, 0xC0,  // R: bitOffset 0, bitLength 16-1, RED | F | S
    0x00, 0x00, 0x00, 0x00,  // samplePosition
    0x00, 0x00, 0x80, 0xBF,  // sampleLower -1.0f
    0x00, 0x00, 0x80, 0x3F,  // sampleUpper 1.0f
};
const Bytes kDfdR32 = {
    0x2C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00, 0x28, 0x00, 0x01, 0x01, 0x01, 0x00,
    0x00, 0x00, 0x00, 0x00,  // texelBlockDimension
    0x04, 0x00, 0x00, 0x00,  // bytesPlane0 4
    0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x1F, 0xC0,  // R: bitOffset 0, bitLength 32-1, RED | F | S
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,
};
const Bytes kDfdRgba16 = {
    0x5C, 0x00, 0x00, 0x00,  // dfdTotalSize 92 = 4 + 24 + 4 * 16
    0x00, 0x00, 0x00, 0x00,
    0x02, 0x00, 0x58, 0x00,  // descriptorBlockSize 88
    0x01, 0x01, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00,
    0x08, 0x00, 0x00, 0x00,  // bytesPlane0 8
    0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x0F, 0xC0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // R @0
    0x10, 0x00, 0x0F, 0xC1, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // G @16
    0x20, 0x00, 0x0F, 0xC2, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // B @32
    0x30, 0x00, 0x0F, 0xCF, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // A(15) @48
};
const Bytes kDfdRgba32 = {
    0x5C, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00, 0x58, 0x00, 0x01, 0x01, 0x01, 0x00,
    0x00, 0x00, 0x00, 0x00,
    0x10, 0x00, 0x00, 0x00,  // bytesPlane0 16
    0x00, 0x00, 0x00, 0x00,
    0x00, 0x00, 0x1F, 0xC0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // R @0
    0x20, 0x00, 0x1F, 0xC1, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // G @32
    0x40, 0x00, 0x1F, 0xC2, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // B @64
    0x60, 0x00, 0x1F, 0xCF, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xBF, 0x00, 0x00, 0x80, 0x3F,  // A(15) @96
};

TEST(Ktx2Layout, DataFormatDescriptorBytesForEachFormat) {
  const std::pair<VkFormat, const Bytes*> cases[] = {{VkFormat::kR16Sfloat, &kDfdR16},
                                                     {VkFormat::kR32Sfloat, &kDfdR32},
                                                     {VkFormat::kR16G16B16A16Sfloat, &kDfdRgba16},
                                                     {VkFormat::kR32G32B32A32Sfloat, &kDfdRgba32}};
  for (const auto& [format, dfd] : cases) {
    SCOPED_TRACE(FormatName(format));
    for (std::uint32_t depth : {0u, 3u}) {
      const Bytes f = Encode(MakeTexture(format, 3, 2, depth));
      EXPECT_EQ(U32(f, 48), 104u);
      EXPECT_EQ(U32(f, 52), dfd->size());
      EXPECT_EQ(Slice(f, 104, dfd->size()), *dfd);
      // §3.10.4: dfdTotalSize = kvdByteOffset - dfdByteOffset.
      EXPECT_EQ(U32(f, 56) - U32(f, 48), dfd->size());
    }
  }
}

// A 3x2x2 VK_FORMAT_R16_SFLOAT 3D texture. DFD 104 + 44 -> 148. KVD at 148,
// sorted byte-wise = by code point (§3.11): 'K' 0x4B < 's' 0x73, and among
// the skybake keys 'A' 0x41 < 'z' 0x7A < 'é' (U+00E9, UTF-8 C3 A9):
//   "KTXorientation\0rdi\0" 19 bytes + 1 padding -> 24 with the length field
//   "KTXwriter\0w\0"        12 bytes + 0 padding -> 16
//   "skybake.A\0abc\0"      14 bytes + 2 padding -> 20
//   "skybake.z\0" "1\0"     12 bytes + 0 padding -> 16
//   "skybake.é\0é\0"        14 bytes + 2 padding -> 20
// kvdByteLength 96 = sum(ceil(len/4)*4) + 5*4 -> ends at 244, already a
// multiple of lcm(2, 4) = 4, so the level starts at 244 without mipPadding.
TEST(Ktx2Layout, KeyValueDataIsSortedPaddedAndNulTerminated) {
  const Texture t = MakeTexture(VkFormat::kR16Sfloat, 3, 2, 2,
                                {{"skybake.z", "1"}, {"skybake.\xC3\xA9", "\xC3\xA9"}, {"skybake.A", "abc"},
                                 {"KTXwriter", "w"}});
  const Bytes f = Encode(t);
  EXPECT_EQ(U32(f, 28), 2u);    // pixelDepth
  EXPECT_EQ(U32(f, 56), 148u);  // kvdByteOffset
  EXPECT_EQ(U32(f, 60), 96u);   // kvdByteLength
  const std::string expected = std::string("\x13\0\0\0KTXorientation\0rdi\0\0", 24) +
                               std::string("\x0C\0\0\0KTXwriter\0w\0", 16) +
                               std::string("\x0E\0\0\0skybake.A\0abc\0\0\0", 20) +
                               std::string("\x0C\0\0\0skybake.z\0" "1\0", 16) +
                               std::string("\x0E\0\0\0skybake.\xC3\xA9\0\xC3\xA9\0\0\0", 20);
  EXPECT_EQ(Slice(f, 148, 96), Ascii(expected));
  EXPECT_EQ(U64(f, 80), 244u);
  EXPECT_EQ(U64(f, 88), 3u * 2u * 2u * 2u);
  EXPECT_EQ(f.size(), 244u + 24u);
}

// VK_FORMAT_R16G16B16A16_SFLOAT (8-byte texels): DFD 104 + 92 -> 196;
// "KTXorientation\0rd\0" 24 + "KTXwriter\0w\0" 16 -> KVD ends at 236, and
// lcm(8, 4) = 8 puts the level at 240 after 4 zero bytes of mipPadding.
TEST(Ktx2Layout, LevelIsAlignedToLcmOfTexelSizeAndFour) {
  const Bytes f = Encode(MakeTexture(VkFormat::kR16G16B16A16Sfloat, 2, 1, 0, {{"KTXwriter", "w"}}));
  EXPECT_EQ(U32(f, 60), 40u);
  EXPECT_EQ(U64(f, 80), 240u);
  EXPECT_EQ(Slice(f, 236, 4), Bytes(4, 0));
  EXPECT_EQ(U64(f, 88), 16u);
  EXPECT_EQ(f.size(), 256u);

  // For every format and a spread of key lengths: the level offset is the
  // smallest multiple of lcm(texel size, 4) at or after the end of the KVD.
  for (VkFormat format : kAllFormats) {
    const std::uint64_t alignment = std::lcm<std::uint64_t>(BytesPerTexel(format), 4);
    for (int n = 0; n < 12; ++n) {
      const Bytes g = Encode(MakeTexture(format, 1, 1, 0, {{"skybake.k", std::string(n, 'x')}}));
      const std::uint64_t kvd_end = U32(g, 56) + U32(g, 60);
      const std::uint64_t offset = U64(g, 80);
      EXPECT_EQ(offset % alignment, 0u) << FormatName(format) << " n=" << n;
      EXPECT_GE(offset, kvd_end);
      EXPECT_LT(offset - kvd_end, alignment);
      EXPECT_EQ(kvd_end % 4, 0u);
    }
  }
}

TEST(Ktx2Layout, DefaultKeysNameTheWriterAndOrientation) {
  const Texture decoded2d = Decode(Encode(MakeTexture(VkFormat::kR32Sfloat, 2, 2, 0)), "2d");
  EXPECT_EQ(decoded2d.key_values.at("KTXorientation"), "rd");
  EXPECT_EQ(decoded2d.key_values.at("KTXwriter").rfind("skybake ", 0), 0u);
  const Texture decoded3d = Decode(Encode(MakeTexture(VkFormat::kR32Sfloat, 2, 2, 2)), "3d");
  EXPECT_EQ(decoded3d.key_values.at("KTXorientation"), "rdi");
  // Caller-supplied values win.
  const Texture custom =
      Decode(Encode(MakeTexture(VkFormat::kR32Sfloat, 2, 2, 0, {{"KTXorientation", "ru"}, {"KTXwriter", "me"}})), "c");
  EXPECT_EQ(custom.key_values.at("KTXorientation"), "ru");
  EXPECT_EQ(custom.key_values.at("KTXwriter"), "me");
}

// ---------------------------------------------------------------------------
// Round trips

TEST(Ktx2RoundTrip, EveryFormatIn2DAnd3D) {
  for (VkFormat format : kAllFormats) {
    for (std::uint32_t depth : {0u, 1u, 4u}) {
      SCOPED_TRACE(std::string(FormatName(format)) + " depth " + std::to_string(depth));
      Texture t = MakeTexture(format, 5, 3, depth, {{"skybake.table", "transmittance"}, {"skybake.empty", ""}});
      const Texture back = Decode(Encode(t), "mem");
      t.key_values.emplace("KTXwriter", back.key_values.at("KTXwriter"));
      t.key_values.emplace("KTXorientation", depth ? "rdi" : "rd");
      EXPECT_TRUE(SameTexture(t, back));
      // Values come back bit for bit (they are exact in half precision too).
      const auto values = UnpackFloats(format, back.data);
      ASSERT_EQ(values.size(), t.TexelCount() * ChannelCount(format));
      for (std::size_t i = 0; i < values.size(); ++i) {
        ASSERT_EQ(values[i], static_cast<float>(static_cast<int>(i % 1000) - 500) / 8.0f);
      }
    }
  }
}

TEST(Ktx2RoundTrip, ThroughFilesWrittenAtomically) {
  const fs::path dir = fs::temp_directory_path() / ("skybake_ktx2_test_" + std::to_string(std::random_device{}()));
  fs::create_directories(dir);
  const fs::path path = dir / "inscatter.ktx2";
  const Texture t = MakeTexture(VkFormat::kR16G16B16A16Sfloat, 8, 4, 6, {{"skybake.command", "skybake bake earth"}});
  WriteFile(path, t);
  const Texture back = ReadFile(path);
  EXPECT_EQ(back.data, t.data);
  EXPECT_EQ(back.key_values.at("skybake.command"), "skybake bake earth");
  // Only the finished file is left behind.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  try {
    ReadFile(dir / "missing.ktx2");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.ktx2"), std::string::npos);
  }
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------
// Encode rejects what the specification forbids

TEST(Ktx2Encode, RejectsReservedMalformedAndUnprefixedKeys) {
  const auto encode_with = [](std::map<std::string, std::string> keys, std::uint32_t depth = 0) {
    Encode(MakeTexture(VkFormat::kR32Sfloat, 1, 1, depth, std::move(keys)));
  };
  EXPECT_THROW(encode_with({{"KTXswizzle", "rgba"}}), InputError);  // reserved prefix (§3.11.2)
  EXPECT_THROW(encode_with({{"ktxCustom", "x"}}), InputError);
  EXPECT_THROW(encode_with({{"author", "x"}}), InputError);       // not in skybake's namespace
  EXPECT_THROW(encode_with({{"", "x"}}), InputError);
  EXPECT_THROW(encode_with({{std::string("skybake.a\0b", 11), "x"}}), InputError);  // NUL ends the key
  EXPECT_THROW(encode_with({{"skybake.a", std::string("x\0y", 3)}}), InputError);
  EXPECT_THROW(encode_with({{"skybake.\xFF", "x"}}), InputError);  // not UTF-8
  EXPECT_THROW(encode_with({{"skybake.a", "\xC0\xAF"}}), InputError);  // overlong
  EXPECT_THROW(encode_with({{"skybake.a", "\xED\xA0\x80"}}), InputError);  // surrogate
  EXPECT_THROW(encode_with({{"KTXorientation", "rdi"}}), InputError);      // 3D value on 2D (§5.2)
  EXPECT_THROW(encode_with({{"KTXorientation", "rd"}}, 2), InputError);    // 2D value on 3D
  EXPECT_THROW(encode_with({{"KTXorientation", "xd"}}), InputError);
  EXPECT_NO_THROW(encode_with({{"skybake.\xE2\x84\xAB", "\xF0\x9F\x8C\x85"}}));
}

TEST(Ktx2Encode, RejectsDataThatDoesNotMatchTheDimensions) {
  Texture t = MakeTexture(VkFormat::kR32G32B32A32Sfloat, 2, 2, 0);
  t.data.pop_back();
  EXPECT_THROW(Encode(t), InternalError);
  Texture zero = MakeTexture(VkFormat::kR32Sfloat, 1, 1, 0);
  zero.width = 0;
  zero.data.clear();
  EXPECT_THROW(Encode(zero), InternalError);
}

}  // namespace
}  // namespace skybake::ktx2
