// KTX2 decoding of foreign, truncated, corrupt and unsupported files, and the
// sample files for the independent parser (tests/ktx2_crosscheck).
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
// Decode: foreign, truncated, corrupt and unsupported files

TEST(Ktx2Decode, RejectsFilesThatAreNotKtx2) {
  EXPECT_NE(DecodeError({}).find("not a KTX2 file"), std::string::npos);
  EXPECT_NE(DecodeError(Ascii("hello, this is a text file of some length")).find("not a KTX2 file"),
            std::string::npos);
  Bytes ktx1 = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
  ktx1.resize(200, 0);
  EXPECT_NE(DecodeError(ktx1).find("KTX 1.1"), std::string::npos);
  // A CR-LF translation damages the identifier (§3.1's rationale).
  Bytes f = Encode(MakeTexture(VkFormat::kR32Sfloat, 2, 2, 0));
  f.erase(f.begin() + 8);
  EXPECT_NE(DecodeError(f).find("not a KTX2 file"), std::string::npos);
}

TEST(Ktx2Decode, EveryTruncationIsReportedAsTruncated) {
  for (VkFormat format : kAllFormats) {
    for (std::uint32_t depth : {0u, 2u}) {
      const Bytes f = Encode(MakeTexture(format, 3, 2, depth, {{"skybake.x", "abcde"}}));
      for (std::size_t n = 1; n < f.size(); ++n) {
        const std::string error = DecodeError(Bytes(f.begin(), f.begin() + static_cast<std::ptrdiff_t>(n)));
        ASSERT_NE(error.find("test.ktx2: truncated"), std::string::npos)
            << FormatName(format) << " cut at " << n << " of " << f.size() << ": '" << error << "'";
      }
    }
  }
}

// Flipping any single bit of the header, index or DFD must be detected. The
// one exception is levelCount 1 -> 0, which is still a valid file with the
// same meaning (§3.7: both describe a base level only).
TEST(Ktx2Decode, EveryBitFlipInHeaderIndexAndDfdIsDetected) {
  for (VkFormat format : kAllFormats) {
    for (std::uint32_t depth : {0u, 2u}) {
      const Bytes f = Encode(MakeTexture(format, 3, 2, depth, {{"skybake.x", "abc"}}));
      const Texture original = Decode(f, "original");
      const std::size_t dfd_end = U32(f, 48) + U32(f, 52);
      for (std::size_t at = 0; at < dfd_end; ++at) {
        for (int bit = 0; bit < 8; ++bit) {
          Bytes g = f;
          g[at] ^= static_cast<std::uint8_t>(1u << bit);
          const bool benign = at == 40 && bit == 0;
          try {
            const Texture t = Decode(g, "test.ktx2");
            ASSERT_TRUE(benign) << FormatName(format) << ": flip at byte " << at << " bit " << bit << " not detected";
            EXPECT_TRUE(SameTexture(t, original));
          } catch (const IoError& e) {
            ASSERT_FALSE(benign) << e.what();
            ASSERT_EQ(std::string(e.what()).rfind("test.ktx2: ", 0), 0u) << e.what();
          }
        }
      }
    }
  }
}

// Flips in the key/value data and the mip padding must never crash the
// reader. A flipped letter can be a different valid key or value, and some
// length flips only move a NUL between value and padding, so not every flip
// is an error; but lengths that run past kvdByteLength and non-zero padding
// always are, and whatever is accepted still has the original level.
TEST(Ktx2Decode, BitFlipsInKeyValueDataAreDetectedOrHarmless) {
  const Bytes f = Encode(MakeTexture(VkFormat::kR16G16B16A16Sfloat, 2, 1, 0, {{"skybake.x", "abc"}}));
  const Texture original = Decode(f, "original");
  const std::size_t kvd_begin = U32(f, 56);
  const std::size_t kvd_end = kvd_begin + U32(f, 60);
  const std::size_t level_begin = static_cast<std::size_t>(U64(f, 80));
  // Bytes that must always be caught: the high bytes of each
  // keyAndValueByteLength (any set bit there means >= 256 bytes, past the
  // end), valuePadding and mipPadding.
  std::vector<bool> must_detect(f.size(), false);
  for (std::size_t at = kvd_begin; at < kvd_end;) {
    const std::uint32_t length = U32(f, at);
    for (std::size_t k = 1; k < 4; ++k) must_detect[at + k] = true;
    const std::size_t padded = (length + 3) / 4 * 4;
    for (std::size_t p = at + 4 + length; p < at + 4 + padded; ++p) must_detect[p] = true;
    at += 4 + padded;
  }
  for (std::size_t p = kvd_end; p < level_begin; ++p) must_detect[p] = true;
  int detected = 0;
  for (std::size_t at = kvd_begin; at < level_begin; ++at) {
    for (int bit = 0; bit < 8; ++bit) {
      Bytes g = f;
      g[at] ^= static_cast<std::uint8_t>(1u << bit);
      try {
        const Texture t = Decode(g, "test.ktx2");
        ASSERT_FALSE(must_detect[at]) << "flip at byte " << at << " bit " << bit << " not detected";
        EXPECT_EQ(t.data, original.data);
        EXPECT_EQ(t.width, original.width);
      } catch (const IoError&) {
        ++detected;
      }
    }
  }
  EXPECT_GT(detected, 0);
}

// Random multi-byte damage plus random truncation or extension, with a fixed
// seed: the reader either rejects the file with an IoError or returns a
// texture whose data size matches its header. (Run under AddressSanitizer,
// this also shows that no read leaves the buffer.)
TEST(Ktx2Decode, RandomDamageNeverCrashes) {
  std::mt19937 random(20240611u);
  for (VkFormat format : kAllFormats) {
    const Bytes f = Encode(MakeTexture(format, 4, 3, 2, {{"skybake.a", "xyz"}, {"skybake.bb", ""}}));
    for (int trial = 0; trial < 3000; ++trial) {
      Bytes g = f;
      const int flips = 1 + static_cast<int>(random() % 8);
      for (int k = 0; k < flips; ++k) g[random() % g.size()] = static_cast<std::uint8_t>(random());
      if (trial % 3 == 1) g.resize(random() % g.size());
      if (trial % 3 == 2) g.resize(g.size() + random() % 64, static_cast<std::uint8_t>(random()));
      try {
        const Texture t = Decode(g, "fuzz");
        ASSERT_EQ(t.data.size(), t.TexelCount() * BytesPerTexel(t.format));
      } catch (const IoError&) {
      }
    }
  }
}

TEST(Ktx2Decode, RejectsCorruptIndexAndLevelFields) {
  const Bytes f = Encode(MakeTexture(VkFormat::kR32G32B32A32Sfloat, 2, 2, 0, {{"skybake.a", "1"}, {"skybake.b", "2"}}));
  const auto expect_error = [](Bytes g, const std::string& needle) {
    const std::string error = DecodeError(g);
    EXPECT_NE(error.find(needle), std::string::npos) << "got '" << error << "', wanted '" << needle << "'";
  };
  Bytes g;
  g = f, SetU32(g, 60, 0xFFFFFFFFu), expect_error(g, "truncated");               // kvdByteLength
  g = f, SetU64(g, 88, 1ull << 63), expect_error(g, "corrupt");                 // level byteLength
  g = f, SetU64(g, 80, ~0ull), expect_error(g, "corrupt level index");          // level byteOffset
  g = f, SetU64(g, 96, 65), expect_error(g, "uncompressedByteLength");
  g = f, SetU32(g, 20, 0xFFFFFFFFu), SetU32(g, 24, 0xFFFFFFFFu), expect_error(g, "overflows");
  g = f, SetU32(g, 20, 0), expect_error(g, "pixelWidth is 0");
  g = f, SetU64(g, 72, 16), expect_error(g, "global data");
  g = f, SetU32(g, 16, 2), expect_error(g, "typeSize");
  g = f, g.push_back(0), expect_error(g, "bytes after the level data");
  g = f, g[U64(f, 80) - 1] = 1, expect_error(g, "mipPadding");
  // Key order and uniqueness (§3.11): renaming a key in place keeps every
  // length intact, so only the order check can catch it.
  Bytes dup = f;
  bool patched = false;
  for (std::size_t i = U32(f, 56); i + 9 < dup.size(); ++i) {
    if (std::string(dup.begin() + i, dup.begin() + i + 9) == "skybake.b") {
      dup[i + 8] = 'a';
      patched = true;
      break;
    }
  }
  ASSERT_TRUE(patched);
  expect_error(dup, "duplicate key 'skybake.a'");
  for (std::size_t i = U32(f, 56); i + 9 < dup.size(); ++i) {
    if (std::string(dup.begin() + i, dup.begin() + i + 9) == "skybake.a") {
      dup[i + 8] = 'c';  // first key now sorts after the second
      break;
    }
  }
  expect_error(dup, "keys not sorted");
}

TEST(Ktx2Decode, ReportsValidButUnsupportedFilesAsUnsupported) {
  const Bytes f = Encode(MakeTexture(VkFormat::kR32Sfloat, 4, 4, 0));
  const auto expect_unsupported = [](const Bytes& g, const std::string& needle) {
    const std::string error = DecodeError(g);
    EXPECT_NE(error.find("unsupported"), std::string::npos) << error;
    EXPECT_NE(error.find(needle), std::string::npos) << error;
  };
  Bytes g;
  g = f, SetU32(g, 40, 3), expect_unsupported(g, "3 mip levels");
  g = f, SetU32(g, 44, 3), expect_unsupported(g, "supercompressionScheme 3");  // ZLIB
  g = f, SetU32(g, 12, 37), expect_unsupported(g, "vkFormat 37");
  g = f, SetU32(g, 32, 2), expect_unsupported(g, "array");
  g = f, SetU32(g, 36, 6), expect_unsupported(g, "cubemap");
  g = f, SetU32(g, 24, 0), expect_unsupported(g, "1D");
  g = f, g[104 + 12 + 2] = 2, expect_unsupported(g, "transfer function 2");  // sRGB
  // levelCount 0 ("generate mipmaps if needed") is read like 1.
  g = f, SetU32(g, 40, 0);
  EXPECT_EQ(DecodeError(g), "");
}

// ---------------------------------------------------------------------------
// Sample files for the independent parser (tests/ktx2_crosscheck): written to
// $SKYBAKE_KTX2_SAMPLE_DIR when set (the ktx2_crosscheck ctest entry sets it),
// otherwise to a temporary directory, and read back here as well.

TEST(Ktx2CrossCheck, WritesSampleSet) {
  const char* env_dir = std::getenv("SKYBAKE_KTX2_SAMPLE_DIR");
  const fs::path dir = env_dir ? fs::path(env_dir)
                               : fs::temp_directory_path() / ("skybake_ktx2_samples_" + std::to_string(std::random_device{}()));
  EnsureWritableDirectory(dir);
  nlohmann::json manifest = nlohmann::json::array();
  for (VkFormat format : kAllFormats) {
    for (std::uint32_t depth : {0u, 5u}) {
      const std::string name = std::string(FormatName(format)) + (depth ? "_3d" : "_2d");
      const Texture t = MakeTexture(format, 7, 3, depth,
                                    {{"skybake.table", depth ? "inscatter" : "transmittance"},
                                     {"skybake.command", "skybake bake earth --out tables"},
                                     {"skybake.\xC3\xA9t\xC3\xA9", "\xC3\xA9t\xC3\xA9 \xE2\x98\x80"},
                                     {"skybake.empty", ""}});
      WriteFile(dir / (name + ".ktx2"), t);
      WriteFileAtomically(dir / (name + ".level0.bin"),
                          std::string_view(reinterpret_cast<const char*>(t.data.data()), t.data.size()));
      const Texture back = ReadFile(dir / (name + ".ktx2"));
      EXPECT_EQ(back.data, t.data);
      // What the file is meant to hold: the caller's keys plus the two Encode adds.
      nlohmann::json keys = nlohmann::json::object();
      for (const auto& [key, value] : t.key_values) keys[key] = value;
      keys["KTXwriter"] = std::string("skybake ") + SKYBAKE_VERSION;
      keys["KTXorientation"] = depth ? "rdi" : "rd";
      EXPECT_EQ(back.key_values.size(), keys.size());
      manifest.push_back({{"file", name + ".ktx2"},
                          {"levelData", name + ".level0.bin"},
                          {"vkFormat", static_cast<std::uint32_t>(format)},
                          {"pixelWidth", t.width},
                          {"pixelHeight", t.height},
                          {"pixelDepth", t.depth},
                          {"levelCount", 1},
                          {"levelByteLength", t.data.size()},
                          {"keyValue", keys}});
    }
  }
  WriteFileAtomically(dir / "manifest.json", manifest.dump(2));
  if (!env_dir) fs::remove_all(dir);
}

}  // namespace
}  // namespace skybake::ktx2
