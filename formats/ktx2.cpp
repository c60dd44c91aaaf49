#include "formats/ktx2.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <numeric>
#include <sstream>
#include <string_view>

#include <Imath/half.h>
#include <zstd.h>

#include "core/errors.h"
#include "core/file_io.h"
#include "core/float_bits.h"
#include "core/version.h"

namespace skybake::ktx2 {

namespace {

// §3.1: «KTX 20»\r\n\x1A\n
constexpr std::uint8_t kIdentifier[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32,
                                          0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};

// §2 File Structure: identifier (12) + nine UInt32 header fields (36) + the
// index (four UInt32 and two UInt64: 32) = 80 bytes, then one 24-byte level
// index entry per level.
constexpr std::size_t kHeaderSize = 80;
constexpr std::size_t kLevelIndexEntrySize = 24;
constexpr std::size_t kDfdOffset = kHeaderSize + kLevelIndexEntrySize;  // one level

// Khronos Data Format Specification 1.4 (KDF) enumerants.
constexpr std::uint32_t kDfModelRgbsda = 1;      // KDF §5.5
constexpr std::uint32_t kDfPrimariesBt709 = 1;   // KDF §5.7
constexpr std::uint32_t kDfTransferLinear = 1;   // KDF §5.8
constexpr std::uint32_t kDfFlagsStraight = 0;    // KDF §5.9, KHR_DF_FLAG_ALPHA_STRAIGHT
constexpr std::uint32_t kDfVersionNumber = 2;    // KDF §5.3
constexpr std::uint32_t kDfQualifierFloat = 0x80;   // KDF §5.15, F bit
constexpr std::uint32_t kDfQualifierSigned = 0x40;  // KDF §5.15, S bit
constexpr std::uint32_t kDfChannelAlpha = 15;       // KDF §5.5, KHR_DF_CHANNEL_RGBSDA_ALPHA

void PutU32(std::vector<std::uint8_t>& out, std::size_t at, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<std::uint8_t>(value >> (8 * i));
}
void PutU64(std::vector<std::uint8_t>& out, std::size_t at, std::uint64_t value) {
  for (int i = 0; i < 8; ++i) out[at + i] = static_cast<std::uint8_t>(value >> (8 * i));
}
// Callers check bounds before reading.
std::uint32_t GetU32(const std::vector<std::uint8_t>& in, std::size_t at) {
  std::uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value |= static_cast<std::uint32_t>(in[at + i]) << (8 * i);
  return value;
}
std::uint64_t GetU64(const std::vector<std::uint8_t>& in, std::size_t at) {
  std::uint64_t value = 0;
  for (int i = 0; i < 8; ++i) value |= static_cast<std::uint64_t>(in[at + i]) << (8 * i);
  return value;
}

bool CheckedMul(std::uint64_t a, std::uint64_t b, std::uint64_t* out) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return false;
  *out = a * b;
  return true;
}

// Level 0 byte length per §3.13 levelImages: num_blocks_x * num_blocks_y *
// num_blocks_z * texel block size, where a block is one texel for
// uncompressed formats and num_blocks_z = max(1, pixelDepth).
bool LevelByteLength(VkFormat format, std::uint64_t width, std::uint64_t height, std::uint64_t depth,
                     std::uint64_t* out) {
  std::uint64_t n = 0;
  return CheckedMul(width, std::max<std::uint64_t>(height, 1), &n) &&
         CheckedMul(n, std::max<std::uint64_t>(depth, 1), &n) && CheckedMul(n, BytesPerTexel(format), out);
}

// §3.13.2 mipPadding: levels start at multiples of lcm(texel block size, 4).
std::uint64_t LevelAlignment(VkFormat format) {
  return std::lcm<std::uint64_t, std::uint64_t>(BytesPerTexel(format), 4);
}

std::uint64_t AlignUp(std::uint64_t value, std::uint64_t alignment) {
  return (value + alignment - 1) / alignment * alignment;
}

// The Data Format Descriptor as 32-bit words (dfdTotalSize first), following
// the Basic Data Format Descriptor Block layout (KDF §5) for an unpacked
// little-endian float format: one sample per channel, channels consecutive.
std::vector<std::uint32_t> DfdWords(VkFormat format) {
  const std::uint32_t channels = static_cast<std::uint32_t>(ChannelCount(format));
  const std::uint32_t bits = static_cast<std::uint32_t>(BytesPerChannel(format) * 8);
  const std::uint32_t block_size = 24 + 16 * channels;  // KDF §5.4
  std::vector<std::uint32_t> words;
  words.push_back(4 + block_size);  // dfdTotalSize counts itself (§3.10.4)
  words.push_back(0);               // vendorId 0 (Khronos) | descriptorType 0 << 17 (basic)
  words.push_back(kDfVersionNumber | (block_size << 16));
  words.push_back(kDfModelRgbsda | (kDfPrimariesBt709 << 8) | (kDfTransferLinear << 16) |
                  (kDfFlagsStraight << 24));
  words.push_back(0);  // texelBlockDimension0..3 store size - 1: a 1x1x1x1 block
  words.push_back(static_cast<std::uint32_t>(BytesPerTexel(format)));  // bytesPlane0; planes 1..3 = 0
  words.push_back(0);                                                   // bytesPlane4..7 = 0
  for (std::uint32_t c = 0; c < channels; ++c) {
    // Channel ids R=0, G=1, B=2, A=15 (KDF §5.5). Float samples set F and,
    // being signed formats, S (KDF §5.15).
    const std::uint32_t channel_id = (channels == 4 && c == 3) ? kDfChannelAlpha : c;
    const std::uint32_t channel_type = channel_id | kDfQualifierFloat | kDfQualifierSigned;
    words.push_back((c * bits) | ((bits - 1) << 16) | (channel_type << 24));  // bitOffset | bitLength-1 | channelType
    words.push_back(0);  // samplePosition0..3: the sample sits at the block origin
    // KDF §5.17: for floating-point channels sampleLower/sampleUpper are
    // floating-point values; a signed channel's nominal range is -1..1. The
    // fields are 32 bits wide, so they hold float32 bit patterns (also for
    // 16-bit halves: only samples wider than 32 bits are widened).
    words.push_back(FloatBits(-1.0f));  // 0xBF800000
    words.push_back(FloatBits(1.0f));   // 0x3F800000
  }
  return words;
}

std::string DfdWordName(std::size_t word) {
  static const char* const kHeaderNames[] = {"dfdTotalSize",
                                             "vendorId/descriptorType",
                                             "versionNumber/descriptorBlockSize",
                                             "colorModel/colorPrimaries/transferFunction/flags",
                                             "texelBlockDimension",
                                             "bytesPlane0..3",
                                             "bytesPlane4..7"};
  if (word < 7) return kHeaderNames[word];
  static const char* const kSampleNames[] = {"bitOffset/bitLength/channelType", "samplePosition",
                                             "sampleLower", "sampleUpper"};
  const std::size_t sample = (word - 7) / 4;
  return "sample " + std::to_string(sample) + " " + kSampleNames[(word - 7) % 4];
}

std::string Hex(std::uint64_t value) {
  std::ostringstream out;
  out << "0x" << std::hex << std::uppercase << value;
  return out.str();
}

// Strict UTF-8 (RFC 3629): no overlong forms, no surrogates, at most U+10FFFF.
bool IsValidUtf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t extra = 0;
    std::uint32_t code = 0, min_code = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      extra = 1, code = c & 0x1F, min_code = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2, code = c & 0x0F, min_code = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3, code = c & 0x07, min_code = 0x10000;
    } else {
      return false;
    }
    if (text.size() - i - 1 < extra) return false;
    for (std::size_t k = 1; k <= extra; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3F);
    }
    if (code < min_code || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return false;
    i += extra + 1;
  }
  return true;
}

bool StartsWith(std::string_view text, std::string_view prefix) {
  return text.size() >= prefix.size() && text.compare(0, prefix.size(), prefix) == 0;
}

// §5.2: 2D /^[rl][du]$/, 3D /^[rl][du][oi]$/.
bool IsValidOrientation(std::string_view value, bool is_3d) {
  if (value.size() != (is_3d ? 3u : 2u)) return false;
  if (value[0] != 'r' && value[0] != 'l') return false;
  if (value[1] != 'd' && value[1] != 'u') return false;
  return !is_3d || value[2] == 'o' || value[2] == 'i';
}

// Byte-wise order of UTF-8 strings equals Unicode code point order, which is
// what §3.11 asks keys to be sorted by.
bool KeyLess(std::string_view a, std::string_view b) {
  return std::lexicographical_compare(
      a.begin(), a.end(), b.begin(), b.end(),
      [](char x, char y) { return static_cast<unsigned char>(x) < static_cast<unsigned char>(y); });
}

void ValidateKeyValue(const std::string& key, const std::string& value, bool is_3d) {
  const std::string where = "KTX2 key '" + key + "'";
  if (key.empty()) throw InputError("KTX2 key/value data: empty key");
  if (key.find('\0') != std::string::npos) throw InputError(where + ": key contains a NUL byte");
  if (!IsValidUtf8(key)) throw InputError(where + ": key is not valid UTF-8");
  if (StartsWith(key, "\xEF\xBB\xBF")) throw InputError(where + ": key starts with a byte order mark");
  // §3.11.2: keys beginning with "KTX" or "ktx" are reserved for the keys the
  // specification defines; skybake writes only these two of them.
  if (StartsWith(key, "KTX") || StartsWith(key, "ktx")) {
    if (key != kWriterKey && key != kOrientationKey) {
      throw InputError(where + ": keys starting with KTX/ktx are reserved by the KTX specification");
    }
  } else if (!StartsWith(key, kSkybakeKeyPrefix)) {
    throw InputError(where + ": metadata keys must start with '" + kSkybakeKeyPrefix + "'");
  }
  if (value.find('\0') != std::string::npos) throw InputError(where + ": value contains a NUL byte");
  if (!IsValidUtf8(value)) throw InputError(where + ": value is not valid UTF-8");
  if (key == kOrientationKey && !IsValidOrientation(value, is_3d)) {
    throw InputError(where + ": '" + value + "' is not a valid orientation for a " +
                     (is_3d ? "3D texture (rl, du, oi: e.g. rdi)" : "2D texture (rl, du: e.g. rd)"));
  }
}

class Reader {
 public:
  Reader(const std::vector<std::uint8_t>& bytes, const std::string& source) : bytes_(bytes), source_(source) {}

  [[noreturn]] void NotKtx2(const std::string& why) const {
    throw IoError(source_ + ": not a KTX2 file" + (why.empty() ? "" : " (" + why + ")"));
  }
  [[noreturn]] void Truncated(const std::string& part, std::uint64_t needed) const {
    throw IoError(source_ + ": truncated: " + part + " needs " + std::to_string(needed) + " bytes, file has " +
                  std::to_string(bytes_.size()));
  }
  [[noreturn]] void Corrupt(const std::string& what) const { throw IoError(source_ + ": corrupt " + what); }
  [[noreturn]] void Unsupported(const std::string& what) const {
    throw IoError(source_ + ": unsupported KTX2 file: " + what);
  }
  // Throws Truncated unless [offset, offset + length) lies inside the file.
  void Require(std::uint64_t offset, std::uint64_t length, const std::string& part) const {
    const std::uint64_t size = bytes_.size();
    if (offset > size || length > size - offset) {
      const std::uint64_t end = length > std::numeric_limits<std::uint64_t>::max() - offset
                                    ? std::numeric_limits<std::uint64_t>::max()
                                    : offset + length;
      Truncated(part, end);
    }
  }

 private:
  const std::vector<std::uint8_t>& bytes_;
  const std::string& source_;
};

// The most a supercompressed level may inflate to: 2 GiB, eight times the
// largest table skybake bakes in a day's use, so that a small corrupt file
// cannot make the reader allocate without bound.
constexpr std::uint64_t kMaxInflatedLevelBytes = std::uint64_t(1) << 31;

// Zstandard (§3.8, scheme notes): one frame holding the whole level.
std::vector<std::uint8_t> ZstdCompress(const std::vector<std::uint8_t>& data, int level) {
  if (level < kZstdMinLevel || level > kZstdMaxLevel) {
    throw InternalError("KTX2 encode: zstd level " + std::to_string(level) + " outside " +
                        std::to_string(kZstdMinLevel) + ".." + std::to_string(kZstdMaxLevel));
  }
  std::vector<std::uint8_t> out(ZSTD_compressBound(data.size()));
  const std::size_t written = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), level);
  if (ZSTD_isError(written)) throw InternalError(std::string("KTX2 encode: zstd: ") + ZSTD_getErrorName(written));
  out.resize(written);
  return out;
}

// The level inflated: exactly `length` bytes from Zstandard frames (skippable
// frames allowed, §3.8 scheme notes), or IoError.
std::vector<std::uint8_t> ZstdDecompress(const std::uint8_t* data, std::uint64_t size, std::uint64_t length,
                                         const Reader& reader) {
  if (length > kMaxInflatedLevelBytes) {
    reader.Unsupported("level of " + std::to_string(length) + " bytes after inflation (skybake reads up to " +
                       std::to_string(kMaxInflatedLevelBytes) + ")");
  }
  // A first frame that states its content size (zstd's encoder writes it)
  // must not promise more than the index does, checked before the level's
  // memory is set aside (further frames may hold the rest).
  const unsigned long long declared = ZSTD_getFrameContentSize(data, static_cast<std::size_t>(size));
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != ZSTD_CONTENTSIZE_ERROR && declared > length) {
    reader.Corrupt("level data: its zstd frame declares " + std::to_string(declared) +
                   " bytes, uncompressedByteLength is " + std::to_string(length));
  }
  std::vector<std::uint8_t> out(static_cast<std::size_t>(length));
  // One byte of room more than expected, so that a level inflating to more
  // than uncompressedByteLength is told apart from one that fits exactly.
  out.resize(out.size() + 1);
  const std::size_t inflated = ZSTD_decompress(out.data(), out.size(), data, static_cast<std::size_t>(size));
  if (ZSTD_isError(inflated)) {
    reader.Corrupt(std::string("level data: zstd: ") + ZSTD_getErrorName(inflated));
  }
  if (inflated != length) {
    reader.Corrupt("level data: inflates to " +
                   (inflated > length ? "more than " + std::to_string(length) : std::to_string(inflated)) +
                   " bytes, uncompressedByteLength is " + std::to_string(length));
  }
  out.resize(static_cast<std::size_t>(length));
  return out;
}

}  // namespace

bool IsSupportedFormat(std::uint32_t vk_format) {
  switch (static_cast<VkFormat>(vk_format)) {
    case VkFormat::kR16Sfloat:
    case VkFormat::kR16G16B16A16Sfloat:
    case VkFormat::kR32Sfloat:
    case VkFormat::kR32G32B32A32Sfloat:
      return true;
  }
  return false;
}

const char* FormatName(VkFormat format) {
  switch (format) {
    case VkFormat::kR16Sfloat: return "VK_FORMAT_R16_SFLOAT";
    case VkFormat::kR16G16B16A16Sfloat: return "VK_FORMAT_R16G16B16A16_SFLOAT";
    case VkFormat::kR32Sfloat: return "VK_FORMAT_R32_SFLOAT";
    case VkFormat::kR32G32B32A32Sfloat: return "VK_FORMAT_R32G32B32A32_SFLOAT";
  }
  return "VK_FORMAT_?";
}

int ChannelCount(VkFormat format) {
  return (format == VkFormat::kR16Sfloat || format == VkFormat::kR32Sfloat) ? 1 : 4;
}

std::size_t BytesPerChannel(VkFormat format) {
  return (format == VkFormat::kR16Sfloat || format == VkFormat::kR16G16B16A16Sfloat) ? 2 : 4;
}

std::size_t BytesPerTexel(VkFormat format) {
  return BytesPerChannel(format) * static_cast<std::size_t>(ChannelCount(format));
}

std::size_t Texture::TexelCount() const {
  return static_cast<std::size_t>(width) * height * std::max<std::uint32_t>(depth, 1);
}

std::vector<std::uint8_t> Encode(const Texture& texture) {
  const VkFormat format = texture.format;
  if (!IsSupportedFormat(static_cast<std::uint32_t>(format))) {
    throw InternalError("KTX2 encode: unsupported VkFormat " + std::to_string(static_cast<std::uint32_t>(format)));
  }
  // §4.1 Texture Type: 2D needs width, height > 0 and depth 0; 3D all > 0.
  if (texture.width == 0 || texture.height == 0) {
    throw InternalError("KTX2 encode: texture has a zero width or height");
  }
  std::uint64_t level_length = 0;
  if (!LevelByteLength(format, texture.width, texture.height, texture.depth, &level_length) ||
      level_length != texture.data.size()) {
    throw InternalError("KTX2 encode: " + std::to_string(texture.data.size()) + " data bytes for a " +
                        std::to_string(texture.width) + "x" + std::to_string(texture.height) + "x" +
                        std::to_string(texture.depth) + " " + FormatName(format) + " texture, expected " +
                        std::to_string(level_length));
  }

  // Key/value data (§3.11). A std::map holds each key once; its order is
  // byte-wise for std::string, which KeyLess restates explicitly below.
  std::map<std::string, std::string> key_values = texture.key_values;
  key_values.emplace(kWriterKey, std::string("skybake ") + SKYBAKE_VERSION);
  key_values.emplace(kOrientationKey, texture.Is3D() ? "rdi" : "rd");
  std::vector<std::pair<std::string, std::string>> entries(key_values.begin(), key_values.end());
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return KeyLess(a.first, b.first); });
  std::uint64_t kvd_length = 0;
  for (const auto& [key, value] : entries) {
    ValidateKeyValue(key, value, texture.Is3D());
    // keyAndValueByteLength counts the key, its NUL, the value and the value's
    // NUL (§3.11.1); valuePadding rounds each entry up to 4 bytes (§3.11.3).
    kvd_length += 4 + AlignUp(key.size() + 1 + value.size() + 1, 4);
  }

  const std::uint64_t dfd_length = 4 * DfdWords(format).size();
  const std::uint64_t kvd_offset = kDfdOffset + dfd_length;  // DFD, then KVD (§2)
  const bool zstd = texture.supercompression == Supercompression::kZstd;
  std::vector<std::uint8_t> deflated;
  if (zstd) deflated = ZstdCompress(texture.data, texture.zstd_level);
  const std::uint64_t stored_length = zstd ? deflated.size() : level_length;
  // No supercompression global data, so the level follows the key/value data,
  // after mipPadding only without supercompression (§3.13.2: a deflated level
  // is aligned to 1).
  const std::uint64_t level_offset = AlignUp(kvd_offset + kvd_length, zstd ? 1 : LevelAlignment(format));
  const std::uint64_t file_size = level_offset + stored_length;
  if (kvd_length > std::numeric_limits<std::uint32_t>::max() || file_size < level_offset) {
    throw InputError("KTX2 encode: key/value data or level too large");
  }

  // Everything before the level zero-filled (padding included); the level is
  // appended, not written over zeros.
  std::vector<std::uint8_t> out;
  out.reserve(static_cast<std::size_t>(file_size));
  out.resize(static_cast<std::size_t>(level_offset), 0);
  std::memcpy(out.data(), kIdentifier, sizeof(kIdentifier));
  PutU32(out, 12, static_cast<std::uint32_t>(format));                               // vkFormat
  PutU32(out, 16, static_cast<std::uint32_t>(BytesPerChannel(format)));              // typeSize (§3.3)
  PutU32(out, 20, texture.width);                                                    // pixelWidth
  PutU32(out, 24, texture.height);                                                   // pixelHeight
  PutU32(out, 28, texture.depth);                                                    // pixelDepth
  PutU32(out, 32, 0);                                                                // layerCount: not an array
  PutU32(out, 36, 1);                                                                // faceCount: not a cubemap
  PutU32(out, 40, 1);                                                                // levelCount (see ktx2.h)
  PutU32(out, 44, static_cast<std::uint32_t>(texture.supercompression));            // supercompressionScheme
  PutU32(out, 48, static_cast<std::uint32_t>(kDfdOffset));                           // dfdByteOffset
  PutU32(out, 52, static_cast<std::uint32_t>(dfd_length));                           // dfdByteLength
  PutU32(out, 56, kvd_length ? static_cast<std::uint32_t>(kvd_offset) : 0);          // kvdByteOffset
  PutU32(out, 60, static_cast<std::uint32_t>(kvd_length));                           // kvdByteLength
  PutU64(out, 64, 0);                                                                // sgdByteOffset
  PutU64(out, 72, 0);                                                                // sgdByteLength
  PutU64(out, kHeaderSize + 0, level_offset);                                        // levels[0].byteOffset
  PutU64(out, kHeaderSize + 8, stored_length);                                       // levels[0].byteLength
  PutU64(out, kHeaderSize + 16, level_length);                                       // .uncompressedByteLength

  std::size_t at = kDfdOffset;
  for (std::uint32_t word : DfdWords(format)) {
    PutU32(out, at, word);
    at += 4;
  }
  for (const auto& [key, value] : entries) {
    const std::size_t entry_length = key.size() + 1 + value.size() + 1;
    PutU32(out, at, static_cast<std::uint32_t>(entry_length));
    std::memcpy(out.data() + at + 4, key.data(), key.size());
    std::memcpy(out.data() + at + 4 + key.size() + 1, value.data(), value.size());
    at += 4 + static_cast<std::size_t>(AlignUp(entry_length, 4));  // NULs and padding stay 0
  }
  const std::vector<std::uint8_t>& stored = zstd ? deflated : texture.data;
  out.insert(out.end(), stored.begin(), stored.end());
  return out;
}

Texture Decode(const std::vector<std::uint8_t>& bytes, const std::string& source_name) {
  const Reader reader(bytes, source_name);
  const std::uint64_t size = bytes.size();

  // Identifier (§3.1). A short file that starts like one was cut off.
  if (size < sizeof(kIdentifier)) {
    if (size > 0 && std::memcmp(bytes.data(), kIdentifier, bytes.size()) == 0) {
      reader.Truncated("the identifier", sizeof(kIdentifier));
    }
    reader.NotKtx2(size == 0 ? "empty file" : "");
  }
  if (std::memcmp(bytes.data(), kIdentifier, sizeof(kIdentifier)) != 0) {
    if (std::memcmp(bytes.data(), "\xABKTX 11\xBB", 8) == 0) reader.NotKtx2("it is a KTX 1.1 file");
    reader.NotKtx2("");
  }
  reader.Require(0, kHeaderSize, "the header");

  const std::uint32_t vk_format = GetU32(bytes, 12);
  const std::uint32_t type_size = GetU32(bytes, 16);
  const std::uint32_t width = GetU32(bytes, 20);
  const std::uint32_t height = GetU32(bytes, 24);
  const std::uint32_t depth = GetU32(bytes, 28);
  const std::uint32_t layer_count = GetU32(bytes, 32);
  const std::uint32_t face_count = GetU32(bytes, 36);
  const std::uint32_t level_count = GetU32(bytes, 40);
  const std::uint32_t supercompression = GetU32(bytes, 44);
  const std::uint32_t dfd_offset = GetU32(bytes, 48);
  const std::uint32_t dfd_length = GetU32(bytes, 52);
  const std::uint32_t kvd_offset = GetU32(bytes, 56);
  const std::uint32_t kvd_length = GetU32(bytes, 60);
  const std::uint64_t sgd_offset = GetU64(bytes, 64);
  const std::uint64_t sgd_length = GetU64(bytes, 72);

  // Header fields (§3.2-§3.8, §4.1).
  if (supercompression != static_cast<std::uint32_t>(Supercompression::kNone) &&
      supercompression != static_cast<std::uint32_t>(Supercompression::kZstd)) {
    reader.Unsupported("supercompressionScheme " + std::to_string(supercompression) +
                       " (skybake reads 0, none, and 2, Zstandard)");
  }
  const bool zstd = supercompression == static_cast<std::uint32_t>(Supercompression::kZstd);
  if (!IsSupportedFormat(vk_format)) {
    reader.Unsupported("vkFormat " + std::to_string(vk_format) +
                       " (skybake reads VK_FORMAT_R16_SFLOAT, VK_FORMAT_R32_SFLOAT, "
                       "VK_FORMAT_R16G16B16A16_SFLOAT and VK_FORMAT_R32G32B32A32_SFLOAT)");
  }
  const VkFormat format = static_cast<VkFormat>(vk_format);
  if (type_size != BytesPerChannel(format)) {
    reader.Corrupt("header: typeSize " + std::to_string(type_size) + ", expected " +
                   std::to_string(BytesPerChannel(format)) + " for " + FormatName(format));
  }
  if (width == 0) reader.Corrupt("header: pixelWidth is 0");
  if (height == 0) reader.Unsupported("1D texture (pixelHeight 0)");
  if (face_count == 6) reader.Unsupported("cubemap");
  if (face_count != 1) reader.Corrupt("header: faceCount " + std::to_string(face_count) + ", must be 1 or 6");
  if (layer_count != 0) reader.Unsupported("array texture (layerCount " + std::to_string(layer_count) + ")");
  // levelCount 0 and 1 both mean "base level only" (§3.7).
  if (level_count > 1) reader.Unsupported(std::to_string(level_count) + " mip levels");

  // Index (§3.9). The sections follow each other in the order of §2, so with
  // one level and no global data every offset is determined.
  reader.Require(kHeaderSize, kLevelIndexEntrySize, "the level index");
  const std::uint64_t level_offset = GetU64(bytes, kHeaderSize);
  const std::uint64_t level_length = GetU64(bytes, kHeaderSize + 8);
  const std::uint64_t level_uncompressed_length = GetU64(bytes, kHeaderSize + 16);

  const std::vector<std::uint32_t> dfd_words = DfdWords(format);
  const std::uint64_t expected_dfd_length = 4 * dfd_words.size();
  if (dfd_offset != kDfdOffset) {
    reader.Corrupt("index: dfdByteOffset " + std::to_string(dfd_offset) + ", expected " +
                   std::to_string(kDfdOffset));
  }
  if (dfd_length != expected_dfd_length) {
    reader.Corrupt("index: dfdByteLength " + std::to_string(dfd_length) + ", expected " +
                   std::to_string(expected_dfd_length) + " for " + FormatName(format));
  }
  if (sgd_offset != 0 || sgd_length != 0) {
    // §3.9.5/§3.9.6: no global data without a scheme that defines it.
    reader.Corrupt("index: supercompression global data without supercompression");
  }
  const std::uint64_t dfd_end = kDfdOffset + expected_dfd_length;
  std::uint64_t kvd_end = dfd_end;
  if (kvd_length == 0) {
    if (kvd_offset != 0) reader.Corrupt("index: kvdByteOffset must be 0 when kvdByteLength is 0");
  } else {
    // §3.10.4: dfdTotalSize must equal kvdByteOffset - dfdByteOffset.
    if (kvd_offset != dfd_end) {
      reader.Corrupt("index: kvdByteOffset " + std::to_string(kvd_offset) + ", expected " + std::to_string(dfd_end));
    }
    kvd_end = dfd_end + kvd_length;
  }

  // Data Format Descriptor (§3.10), word by word against the format's own.
  reader.Require(kDfdOffset, expected_dfd_length, "the data format descriptor");
  for (std::size_t w = 0; w < dfd_words.size(); ++w) {
    const std::uint32_t found = GetU32(bytes, kDfdOffset + 4 * w);
    if (found == dfd_words[w]) continue;
    if (w == 3 && (found & 0xFF) == kDfModelRgbsda) {
      // A legal descriptor that describes data skybake does not write.
      if (((found >> 16) & 0xFF) != kDfTransferLinear) {
        reader.Unsupported("transfer function " + std::to_string((found >> 16) & 0xFF) + " (skybake tables are linear)");
      }
      if (((found >> 8) & 0xFF) != kDfPrimariesBt709) {
        reader.Unsupported("color primaries " + std::to_string((found >> 8) & 0xFF) + " (skybake writes BT.709)");
      }
      reader.Unsupported("data format descriptor flags " + Hex(found >> 24));
    }
    reader.Corrupt("data format descriptor: " + DfdWordName(w) + " is " + Hex(found) + ", expected " +
                   Hex(dfd_words[w]) + " for " + FormatName(format));
  }

  // Key/value data (§3.11).
  Texture texture;
  texture.format = format;
  texture.width = width;
  texture.height = height;
  texture.depth = depth;
  reader.Require(dfd_end, kvd_end - dfd_end, "the key/value data");
  std::uint64_t at = dfd_end;
  std::string previous_key;
  bool have_previous = false;
  while (at < kvd_end) {
    const std::string entry_at = "key/value data at byte " + std::to_string(at) + ": ";
    if (kvd_end - at < 4) reader.Corrupt(entry_at + "entry length runs past kvdByteLength");
    const std::uint32_t entry_length = GetU32(bytes, static_cast<std::size_t>(at));
    at += 4;
    if (entry_length < 2) reader.Corrupt(entry_at + "keyAndValueByteLength " + std::to_string(entry_length) + " < 2");
    if (entry_length > kvd_end - at) reader.Corrupt(entry_at + "entry runs past kvdByteLength");
    const auto* entry = reinterpret_cast<const char*>(bytes.data() + at);
    const auto* nul = static_cast<const char*>(std::memchr(entry, '\0', entry_length));
    if (nul == nullptr) reader.Corrupt(entry_at + "key is not NUL-terminated");
    const std::string key(entry, nul);
    std::string value(nul + 1, entry + entry_length);
    if (!value.empty() && value.back() == '\0') value.pop_back();  // §3.11.1: readers must not rely on it
    if (key.empty()) reader.Corrupt(entry_at + "empty key");
    if (!IsValidUtf8(key) || StartsWith(key, "\xEF\xBB\xBF")) reader.Corrupt(entry_at + "key is not UTF-8 without BOM");
    if (have_previous && !KeyLess(previous_key, key)) {
      reader.Corrupt(entry_at + (key == previous_key ? "duplicate key '" : "keys not sorted at '") + key + "'");
    }
    const std::uint64_t padding = AlignUp(entry_length, 4) - entry_length;
    at += entry_length;
    if (padding > kvd_end - at) reader.Corrupt(entry_at + "valuePadding runs past kvdByteLength");
    for (std::uint64_t p = 0; p < padding; ++p) {
      if (bytes[static_cast<std::size_t>(at + p)] != 0) reader.Corrupt(entry_at + "non-zero valuePadding");
    }
    at += padding;
    if (key == kOrientationKey && !IsValidOrientation(value, depth > 0)) {
      reader.Corrupt("key/value data: KTXorientation '" + value + "' does not fit a " + (depth > 0 ? "3D" : "2D") +
                     " texture");
    }
    texture.key_values.emplace(key, std::move(value));
    previous_key = key;
    have_previous = true;
  }

  // Level index entry and the level itself (§3.9.7, §3.13).
  std::uint64_t expected_level_length = 0;
  if (!LevelByteLength(format, width, height, depth, &expected_level_length)) {
    reader.Corrupt("header: " + std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(depth) +
                   " texture size overflows");
  }
  if (!zstd && level_uncompressed_length != level_length) {
    reader.Corrupt("level index: uncompressedByteLength " + std::to_string(level_uncompressed_length) +
                   " differs from byteLength " + std::to_string(level_length));
  }
  if (level_uncompressed_length != expected_level_length) {
    reader.Corrupt("level index: uncompressedByteLength " + std::to_string(level_uncompressed_length) +
                   ", expected " + std::to_string(expected_level_length) + " for " + std::to_string(width) + "x" +
                   std::to_string(height) + "x" + std::to_string(depth) + " " + FormatName(format));
  }
  const std::uint64_t expected_level_offset = AlignUp(kvd_end, zstd ? 1 : LevelAlignment(format));
  if (level_offset != expected_level_offset) {
    reader.Corrupt("level index: byteOffset " + std::to_string(level_offset) + ", expected " +
                   std::to_string(expected_level_offset));
  }
  reader.Require(kvd_end, level_offset - kvd_end, "the mip padding");
  for (std::uint64_t p = kvd_end; p < level_offset; ++p) {
    if (bytes[static_cast<std::size_t>(p)] != 0) reader.Corrupt("mipPadding: non-zero byte at " + std::to_string(p));
  }
  reader.Require(level_offset, level_length, "the level data");
  if (size != level_offset + level_length) {
    reader.Corrupt("file: " + std::to_string(size - level_offset - level_length) + " bytes after the level data");
  }
  if (zstd) {
    texture.supercompression = Supercompression::kZstd;
    texture.data = ZstdDecompress(bytes.data() + level_offset, level_length, level_uncompressed_length, reader);
  } else {
    texture.data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(level_offset), bytes.end());
  }
  return texture;
}

void WriteFile(const std::filesystem::path& path, const Texture& texture) {
  const std::vector<std::uint8_t> bytes = Encode(texture);
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

Texture ReadFile(const std::filesystem::path& path) { return Decode(ReadFileBytes(path), path.string()); }

std::vector<std::uint8_t> PackChannels(VkFormat format, const float* values, std::size_t texels, int channels) {
  const int stored = ChannelCount(format);
  if (channels < 1 || channels > stored) {
    throw InternalError("KTX2 pack: " + std::to_string(channels) + " channels for " + FormatName(format));
  }
  const std::size_t channel_bytes = BytesPerChannel(format);
  std::vector<std::uint8_t> out(texels * stored * channel_bytes, 0);
  for (std::size_t i = 0; i < texels; ++i) {
    for (int c = 0; c < channels; ++c) {
      const float v = values[i * channels + c];
      const std::uint32_t bits = channel_bytes == 2 ? Imath::half(v).bits() : FloatBits(v);
      std::uint8_t* to = &out[(i * stored + c) * channel_bytes];
      for (std::size_t b = 0; b < channel_bytes; ++b) to[b] = static_cast<std::uint8_t>(bits >> (8 * b));
    }
  }
  return out;
}

std::vector<std::uint8_t> PackFloats(VkFormat format, const std::vector<float>& values) {
  const int channels = ChannelCount(format);
  if (values.size() % channels != 0) {
    throw InternalError("KTX2 pack: " + std::to_string(values.size()) + " values is not a whole number of " +
                        FormatName(format) + " texels");
  }
  return PackChannels(format, values.data(), values.size() / channels, channels);
}

LargeBuffer<float> UnpackFloats(VkFormat format, const std::vector<std::uint8_t>& data) {
  const std::size_t channel_bytes = BytesPerChannel(format);
  if (data.size() % channel_bytes != 0) {
    throw InternalError("KTX2 unpack: " + std::to_string(data.size()) + " bytes is not a whole number of " +
                        FormatName(format) + " channels");
  }
  LargeBuffer<float> out(data.size() / channel_bytes);
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::uint32_t bits = 0;
    for (std::size_t b = 0; b < channel_bytes; ++b) bits |= static_cast<std::uint32_t>(data[i * channel_bytes + b]) << (8 * b);
    if (channel_bytes == 2) {
      out[i] = static_cast<float>(Imath::half(Imath::half::FromBits, static_cast<std::uint16_t>(bits)));
    } else {
      out[i] = FloatFromBits(bits);
    }
  }
  return out;
}

}  // namespace skybake::ktx2
