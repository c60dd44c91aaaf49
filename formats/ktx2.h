// KTX 2.0 writer and reader for skybake's lookup tables, written against the
// Khronos "KTX File Format Specification" 2.0 and the Khronos Data Format
// Specification 1.4 (Basic Data Format Descriptor). Section numbers in
// comments refer to the KTX 2.0 specification unless marked "KDF".
//
// Scope: uncompressed float textures, one mip level, no arrays, no cubemaps,
// stored as is or supercompressed with Zstandard (§3.8 scheme 2, RFC 8478).
// 2D textures have depth 0; 3D textures (the 4D inscatter table is stored as
// one) have depth > 0.
//
// Encode writes levelCount = 1 (not 0): §3.7 gives 1 the meaning "only the
// base level, and the texture isn't meant to have other levels", naming a LUT
// as the example, while 0 asks loaders to generate mipmaps, which would
// average table entries that are not neighbours in any physical sense.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/large_buffer.h"

namespace skybake::ktx2 {

// The VkFormat values from the Vulkan specification (enum VkFormat).
enum class VkFormat : std::uint32_t {
  kR16Sfloat = 76,            // VK_FORMAT_R16_SFLOAT
  kR16G16B16A16Sfloat = 97,   // VK_FORMAT_R16G16B16A16_SFLOAT
  kR32Sfloat = 100,           // VK_FORMAT_R32_SFLOAT
  kR32G32B32A32Sfloat = 109,  // VK_FORMAT_R32G32B32A32_SFLOAT
};

// True for the four formats above.
bool IsSupportedFormat(std::uint32_t vk_format);
const char* FormatName(VkFormat format);  // "VK_FORMAT_R16_SFLOAT", ...
int ChannelCount(VkFormat format);         // 1 or 4
std::size_t BytesPerChannel(VkFormat format);  // 2 or 4
std::size_t BytesPerTexel(VkFormat format);    // the texel block size

// Key names the writer fills in (§5.2, §5.5) and the prefix every other
// caller-supplied key must carry (§3.11.2 reserves "KTX"/"ktx" prefixes).
inline constexpr const char kWriterKey[] = "KTXwriter";
inline constexpr const char kOrientationKey[] = "KTXorientation";
inline constexpr const char kSkybakeKeyPrefix[] = "skybake.";

// supercompressionScheme values (§3.8) skybake writes and reads.
enum class Supercompression : std::uint32_t { kNone = 0, kZstd = 2 };
// Zstandard's levels (1 fastest ... 22 smallest) and the one used where none
// is named, zstd's own default: on the default set's float tables the
// levels up to 15 store within 1 % of each other, and 3 takes about 0.2 s
// per 16.8 MB table where 19 takes 20 s for 3 % less.
inline constexpr int kZstdMinLevel = 1, kZstdMaxLevel = 22, kZstdDefaultLevel = 3;

struct Texture {
  VkFormat format = VkFormat::kR32G32B32A32Sfloat;
  std::uint32_t width = 0, height = 0, depth = 0;  // depth 0 = 2D texture
  // Level 0, tightly packed, little-endian, x fastest, then y, then z; for
  // RGBA formats the channels of one texel are consecutive (R, G, B, A).
  std::vector<std::uint8_t> data;
  // Key/value metadata as UTF-8 strings. Encode adds KTXwriter
  // ("skybake <version>") and KTXorientation ("rd" for 2D, "rdi" for 3D)
  // unless present; other keys must start with "skybake.". Decode returns
  // every key in the file, each value without its terminating NUL.
  std::map<std::string, std::string> key_values;
  // How the level is stored in the file: Encode compresses `data` (always
  // the inflated level) at zstd_level; Decode inflates it and says which.
  Supercompression supercompression = Supercompression::kNone;
  int zstd_level = kZstdDefaultLevel;

  bool Is3D() const { return depth > 0; }
  // Number of texels in level 0: width * height * max(1, depth).
  std::size_t TexelCount() const;
};

// Serialises `texture`. Throws InputError for keys or values the
// specification does not allow (reserved prefix, NUL bytes, invalid UTF-8, a
// KTXorientation that does not fit the texture type) and InternalError for a
// texture whose data size does not match its format and dimensions.
std::vector<std::uint8_t> Encode(const Texture& texture);

// Parses and validates a whole file image: identifier, header, index offsets
// and lengths against the file size, the DFD against the format, the level
// size against the dimensions (after inflation: one complete Zstandard frame
// of exactly uncompressedByteLength bytes), the key/value data, the padding. Throws
// IoError "<source_name>: not a KTX2 file", "...: truncated ...",
// "...: corrupt ..." or "...: unsupported ..." (a valid KTX2 file outside the
// scope above). Never reads outside `bytes`.
Texture Decode(const std::vector<std::uint8_t>& bytes, const std::string& source_name);

// Encode + atomic write (a reader never sees a half-written file).
void WriteFile(const std::filesystem::path& path, const Texture& texture);
// Whole-file read + Decode; errors name `path`.
Texture ReadFile(const std::filesystem::path& path);

// Float texels <-> level bytes for `format`: float32 stored as is, half
// formats converted with round-to-nearest-even (Imath::half). `values`
// holds ChannelCount(format) floats per texel.
std::vector<std::uint8_t> PackFloats(VkFormat format, const std::vector<float>& values);
// The same from `channels` (1 to ChannelCount(format)) floats per texel, the
// format's other channels 0 (an RGB table in an RGBA format).
std::vector<std::uint8_t> PackChannels(VkFormat format, const float* values, std::size_t texels, int channels);
LargeBuffer<float> UnpackFloats(VkFormat format, const std::vector<std::uint8_t>& data);

}  // namespace skybake::ktx2
