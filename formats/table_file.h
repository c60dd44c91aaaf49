// One table file, OpenEXR or KTX2, as bytes in memory: the single codec that
// the bake's writer, the loader, `skybake info` and `skybake convert` share.
//
// A TableImage holds the texels as floats, channels interleaved in the order
// the file stores them, x fastest, then y, then z. Both formats carry the same
// "skybake.*" metadata (EXR string attributes, KTX2 key/value data).
//
// OpenEXR: scanline, RLE, ZIP or uncompressed (ChooseExrCompression), one
// channel per name, float32 or half.
// A 3D table is a vertical atlas of its depth slices (image row = z * height
// + y); the "skybake.size" attribute ("WxHxD") says how to unstack it.
// KTX2: VK_FORMAT_R32G32B32A32_SFLOAT or R16G16B16A16_SFLOAT, one mip level,
// 2D or 3D (formats/ktx2.h). A table with three channels gets an alpha
// channel of zeros there, since Vulkan guarantees no three-channel float
// format for sampled images; "skybake.channels" names the meaningful ones.
//
// Halves are rounded by Imath::half in both formats, so an EXR half table
// and a KTX2 half table hold identical values.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/large_buffer.h"

namespace skybake {

enum class FileFormat { kExr, kKtx2 };
enum class PixelType { kFloat, kHalf };

const char* ToString(FileFormat format);  // "exr", "ktx2"
const char* ToString(PixelType type);     // "float", "half"
const char* FileExtension(FileFormat format);  // ".exr", ".ktx2"
// From "exr" / "ktx2"; nullopt for anything else.
std::optional<FileFormat> ParseFileFormat(const std::string& name);
// From a path's extension (.exr, .ktx2, any case); nullopt for anything else.
std::optional<FileFormat> FileFormatOfPath(const std::filesystem::path& path);

using Metadata = std::map<std::string, std::string>;

// Metadata keys shared by both formats (one name per concept: the manifest
// uses the same words).
inline constexpr const char kTableKey[] = "skybake.table";
inline constexpr const char kEncodingKey[] = "skybake.encoding";
inline constexpr const char kUnitsKey[] = "skybake.units";
inline constexpr const char kWavelengthsKey[] = "skybake.wavelengths_nm";
inline constexpr const char kParametersKey[] = "skybake.parameters";
inline constexpr const char kSizeKey[] = "skybake.size";
inline constexpr const char kLayoutKey[] = "skybake.layout";
inline constexpr const char kChannelsKey[] = "skybake.channels";
inline constexpr const char kAtmosphereKey[] = "skybake.atmosphere";
// EXR only, the counterpart of KTX2's KTXwriter: "skybake <version>".
inline constexpr const char kExrGeneratorKey[] = "skybake.generator";

// How an OpenEXR file's pixels are stored (both lossless). kOther: read from
// a file written with another of OpenEXR's codecs.
enum class ExrCompression { kZip, kRle, kNone, kOther };

struct TableImage {
  FileFormat format = FileFormat::kExr;
  PixelType pixel_type = PixelType::kFloat;
  int width = 0, height = 0, depth = 1;
  bool is_3d = false;  // depth > 1 tables are 3D; a 3D table may also have depth 1
  std::vector<std::string> channel_names;  // as stored ("R", "G", "B", "A" for skybake tables)
  LargeBuffer<float> values;               // channel_names.size() values per texel
  // "skybake.*" keys. Decoding also returns what the encoder adds (KTXwriter,
  // KTXorientation, skybake.generator, skybake.size); encoding sets those itself.
  Metadata metadata;
  // OpenEXR only: as decoded, or as ChooseExrCompression set it for writing.
  ExrCompression exr_compression = ExrCompression::kZip;
  // KTX2 only: the level stored as is (0) or Zstandard-supercompressed at
  // this level (1-22, ktx2::kZstd*Level); a decoded zstd file reads
  // ktx2::kZstdDefaultLevel, the level itself not being recorded.
  int ktx2_zstd_level = 0;

  std::size_t TexelCount() const { return std::size_t(width) * height * depth; }
  // "VK_FORMAT_R32G32B32A32_SFLOAT" (", zstd" appended when supercompressed)
  // for KTX2; for OpenEXR "EXR float RLE", "EXR float ZIP" or "EXR float
  // uncompressed" (half likewise).
  std::string StorageName() const;
};

// The fastest codec that pays: an OpenEXR image is stored with OpenEXR's
// run-length coding (RLE, one pass over the byte-reordered differences of
// neighbouring values, row by row) if a sample of its rows (one in 16,
// spread over the image) shrinks by at least kExrMinimumSaving of its size
// with it, ZIP-compressed if a sample of ZIP's 16-row blocks (4, each in the
// middle of its quarter of the image) shrinks by that much with ZIP and by
// that much more than with RLE, else
// uncompressed. Float tables whose low mantissa bits are noise shrink by a
// few percent with either, at about 20 ns per byte for ZIP; RLE takes the
// runs of zero of dark texels at a fraction of ZIP's cost, and ZIP what
// repeats beyond runs, as in half tables (docs/benchmark.md). No effect on
// KTX2 images.
inline constexpr double kExrMinimumSaving = 0.10;
void ChooseExrCompression(TableImage* image);

// The storage of a file about to be written: for OpenEXR the compression
// ChooseExrCompression picks, for KTX2 Zstandard supercompression at
// `ktx2_zstd_level` (0: stored as is).
void ChooseFileStorage(TableImage* image, int ktx2_zstd_level);

// The channels the file holds: R,G,B,A for every KTX2 table (RGB tables are
// padded), the image's own channels for OpenEXR.
std::vector<std::string> StoredChannels(const TableImage& image);

// The channels that carry data: those "skybake.channels" names (a KTX2 file
// pads an RGB table with an alpha channel), else every stored channel.
// IoError naming `source` if the list names a channel the image lacks.
std::vector<std::string> MeaningfulChannels(const TableImage& image, const std::string& source);

// Serialises `image` in image.format. For KTX2 the channels must be R,G,B or
// R,G,B,A; for OpenEXR any distinct names. InternalError if the values do not
// fit the dimensions, InputError for metadata the format cannot hold.
std::vector<std::uint8_t> EncodeTableImage(const TableImage& image);

// Parses an EXR or KTX2 file image (told apart by their signatures).
// IoError "<source>: ..." for an empty, foreign, truncated or corrupt file and
// for what skybake does not read (deep, subsampled channels, other VkFormats);
// never reads outside `bytes`.
TableImage DecodeTableImage(const std::vector<std::uint8_t>& bytes, const std::string& source);

// The same through files (atomic write; whole-file read).
void WriteTableImage(const std::filesystem::path& path, const TableImage& image);
TableImage ReadTableImage(const std::filesystem::path& path);

}  // namespace skybake
