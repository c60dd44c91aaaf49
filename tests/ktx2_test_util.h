// Byte helpers, sample textures and a decode-error probe shared by the KTX2
// tests (ktx2_test.cpp, ktx2_decode_test.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "formats/ktx2.h"

namespace skybake::ktx2 {

using Bytes = std::vector<std::uint8_t>;

inline constexpr VkFormat kAllFormats[] = {VkFormat::kR16Sfloat, VkFormat::kR32Sfloat, VkFormat::kR16G16B16A16Sfloat,
                                    VkFormat::kR32G32B32A32Sfloat};

inline std::uint32_t U32(const Bytes& b, std::size_t at) {
  return b.at(at) | (b.at(at + 1) << 8) | (b.at(at + 2) << 16) | (static_cast<std::uint32_t>(b.at(at + 3)) << 24);
}
inline std::uint64_t U64(const Bytes& b, std::size_t at) { return U32(b, at) | (static_cast<std::uint64_t>(U32(b, at + 4)) << 32); }
inline void SetU32(Bytes& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b.at(at + i) = static_cast<std::uint8_t>(v >> (8 * i));
}
inline void SetU64(Bytes& b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) b.at(at + i) = static_cast<std::uint8_t>(v >> (8 * i));
}
inline Bytes Slice(const Bytes& b, std::size_t at, std::size_t n) {
  return Bytes(b.begin() + static_cast<std::ptrdiff_t>(at), b.begin() + static_cast<std::ptrdiff_t>(at + n));
}
inline Bytes Ascii(const std::string& s) { return Bytes(s.begin(), s.end()); }

// A texture with distinct, exactly representable texel values (multiples of
// 1/8 up to 128 fit a half's 11-bit significand), including negatives.
inline Texture MakeTexture(VkFormat format, std::uint32_t w, std::uint32_t h, std::uint32_t d,
                    std::map<std::string, std::string> keys = {}) {
  Texture t;
  t.format = format;
  t.width = w;
  t.height = h;
  t.depth = d;
  std::vector<float> values(static_cast<std::size_t>(w) * h * std::max<std::uint32_t>(d, 1) * ChannelCount(format));
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>(static_cast<int>(i % 1000) - 500) / 8.0f;
  t.data = PackFloats(format, values);
  t.key_values = std::move(keys);
  return t;
}

// Runs Decode and returns the IoError message ("" if it did not throw). Any
// other exception type fails the test.
inline std::string DecodeError(const Bytes& bytes) {
  try {
    Decode(bytes, "test.ktx2");
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

inline bool SameTexture(const Texture& a, const Texture& b) {
  return a.format == b.format && a.width == b.width && a.height == b.height && a.depth == b.depth &&
         a.data == b.data && a.key_values == b.key_values;
}

}  // namespace skybake::ktx2
