#include "formats/table_file.h"

#include <OpenEXR/IlmThreadPool.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCheckFile.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIO.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <set>

#include <Imath/half.h>

#include "core/errors.h"
#include "core/file_io.h"
#include "core/large_buffer.h"
#include "core/version.h"
#include "formats/ktx2.h"

namespace fs = std::filesystem;

namespace skybake {

namespace {

// Decoding refuses images with more values than this (a corrupt header could
// otherwise ask for terabytes); skybake's largest default table has 4.2 million.
constexpr std::size_t kMaxValues = std::size_t(1) << 28;

// The OpenEXR codecs skybake writes and names, and OpenEXR's for each.
struct ExrCodec {
  ExrCompression compression;
  Imf::Compression imf;
  const char* name;
};
constexpr ExrCodec kExrCodecs[] = {{ExrCompression::kZip, Imf::ZIP_COMPRESSION, "ZIP"},
                                   {ExrCompression::kRle, Imf::RLE_COMPRESSION, "RLE"},
                                   {ExrCompression::kNone, Imf::NO_COMPRESSION, "uncompressed"}};

// The entry of `compression`; nullptr for kOther.
const ExrCodec* FindExrCodec(ExrCompression compression) {
  for (const ExrCodec& codec : kExrCodecs) {
    if (codec.compression == compression) return &codec;
  }
  return nullptr;
}

constexpr std::uint8_t kExrMagic[4] = {0x76, 0x2F, 0x31, 0x01};
constexpr std::uint8_t kKtx2Magic[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};

// Library messages sometimes span lines; errors are one line.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

std::string SizeString(int width, int height, int depth, bool is_3d) {
  std::string s = std::to_string(width) + "x" + std::to_string(height);
  if (is_3d) s += "x" + std::to_string(depth);
  return s;
}

// Parses "WxH" or "WxHxD"; false for anything else.
bool ParseSize(const std::string& text, std::vector<long long>* dims) {
  dims->clear();
  std::size_t at = 0;
  while (at <= text.size()) {
    std::size_t end = text.find('x', at);
    if (end == std::string::npos) end = text.size();
    const std::string part = text.substr(at, end - at);
    if (part.empty() || part.size() > 9 || !std::all_of(part.begin(), part.end(), ::isdigit)) return false;
    dims->push_back(std::stoll(part));
    at = end + 1;
  }
  return dims->size() == 2 || dims->size() == 3;
}

void CheckShape(const TableImage& image) {
  if (image.width <= 0 || image.height <= 0 || image.depth <= 0 || (!image.is_3d && image.depth != 1)) {
    throw InternalError("table image: invalid size " + SizeString(image.width, image.height, image.depth, image.is_3d));
  }
  if (image.channel_names.empty() || image.values.size() != image.TexelCount() * image.channel_names.size()) {
    throw InternalError("table image: " + std::to_string(image.values.size()) + " values for " +
                        std::to_string(image.TexelCount()) + " texels of " +
                        std::to_string(image.channel_names.size()) + " channels");
  }
}

// ---------------------------------------------------------------------------
// OpenEXR through memory streams, so the bytes written are the bytes hashed
// and the bytes hashed are the bytes decoded.

class MemoryOStream : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (position_ + n > bytes_.size()) bytes_.resize(position_ + n);
    std::memcpy(bytes_.data() + position_, c, n);
    position_ += n;
  }
  std::uint64_t tellp() override { return position_; }
  void seekp(std::uint64_t position) override { position_ = position; }
  std::vector<std::uint8_t>& bytes() { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
  std::uint64_t position_ = 0;
};

class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const std::vector<std::uint8_t>& bytes, const std::string& name)
      : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || position_ > bytes_.size() || std::uint64_t(n) > bytes_.size() - position_) {
      throw std::runtime_error("unexpected end of file");
    }
    std::memcpy(c, bytes_.data() + position_, n);
    position_ += n;
    return position_ < bytes_.size();
  }
  std::uint64_t tellg() override { return position_; }
  void seekg(std::uint64_t position) override { position_ = position; }

 private:
  const std::vector<std::uint8_t>& bytes_;
  std::uint64_t position_ = 0;
};

std::vector<std::uint8_t> EncodeExr(const TableImage& image) {
  std::set<std::string> distinct(image.channel_names.begin(), image.channel_names.end());
  if (distinct.size() != image.channel_names.size()) throw InternalError("table image: duplicate channel names");
  const int channels = static_cast<int>(image.channel_names.size());
  const int rows = image.height * image.depth;  // the atlas
  Imf::Header header(image.width, rows);
  const ExrCodec* codec = FindExrCodec(image.exr_compression);
  if (codec == nullptr) throw InternalError("EXR encode: no compression chosen");
  header.compression() = codec->imf;
  const bool half = image.pixel_type == PixelType::kHalf;
  for (const std::string& name : image.channel_names) {
    header.channels().insert(name, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
  }
  for (const auto& [key, value] : image.metadata) header.insert(key, Imf::StringAttribute(value));
  header.insert(kSizeKey, Imf::StringAttribute(SizeString(image.width, image.height, image.depth, image.is_3d)));
  header.insert(kExrGeneratorKey, Imf::StringAttribute("skybake " SKYBAKE_VERSION));

  // Planar copies in the stored pixel type; halves rounded by Imath::half so both
  // formats agree bit for bit.
  const std::size_t texels = image.TexelCount();
  LargeBuffer<float> floats;
  LargeBuffer<std::uint16_t> halves;
  if (half) {
    halves.resize(texels * channels);
    for (std::size_t i = 0; i < texels; ++i) {
      for (int c = 0; c < channels; ++c) halves[c * texels + i] = Imath::half(image.values[i * channels + c]).bits();
    }
  } else {
    floats.resize(texels * channels);
    for (std::size_t i = 0; i < texels; ++i) {
      for (int c = 0; c < channels; ++c) floats[c * texels + i] = image.values[i * channels + c];
    }
  }
  MemoryOStream stream;
  // Room for the file as stored uncompressed (header, and per block of
  // scanlines its offset, row and size), so that the buffer is not copied as
  // it grows; compressed files take less, or a few bytes more.
  stream.bytes().reserve(texels * channels * (half ? 2 : 4) + std::size_t(rows) * 16 + (std::size_t(1) << 16));
  try {
    // Every block of scanlines encoded on the calling thread: with threads
    // in OpenEXR's global pool its writer hands each block to the pool as a
    // task, whatever the file's thread count, and waits for it; for the
    // one-scanline blocks of the uncompressed and RLE files the handoffs
    // cost more than the encoding (measured in docs/benchmark.md, seventh
    // round). The writer encodes one file per core instead (WriteStagedSet).
    static const bool kEncodeOnCallingThread = [] {
      IlmThread::ThreadPool::globalThreadPool().setNumThreads(0);
      return true;
    }();
    (void)kEncodeOnCallingThread;
    Imf::OutputFile file(stream, header, 0);
    Imf::FrameBuffer frame;
    const std::size_t bytes_per_value = half ? 2 : 4;
    for (int c = 0; c < channels; ++c) {
      char* base = half ? reinterpret_cast<char*>(halves.data() + c * texels)
                        : reinterpret_cast<char*>(floats.data() + c * texels);
      frame.insert(image.channel_names[c], Imf::Slice(half ? Imf::HALF : Imf::FLOAT, base, bytes_per_value,
                                                      bytes_per_value * image.width));
    }
    file.setFrameBuffer(frame);
    file.writePixels(rows);
  } catch (const std::exception& e) {
    throw InternalError("cannot encode EXR: " + OneLine(e.what()));
  }
  return std::move(stream.bytes());
}

TableImage DecodeExr(const std::vector<std::uint8_t>& bytes, const std::string& source) {
  // OpenEXR's own validator first: it walks every part and chunk with
  // bounds checks, so a damaged file is refused before the reader trusts it.
  if (Imf::checkOpenEXRFile(reinterpret_cast<const char*>(bytes.data()), bytes.size(), /*reduceMemory=*/true,
                            /*reduceTime=*/true, /*enableCoreCheck=*/true)) {
    throw IoError(source + ": truncated or corrupt EXR file (OpenEXR's file check failed)");
  }
  TableImage image;
  image.format = FileFormat::kExr;
  try {
    MemoryIStream stream(bytes, source);
    Imf::InputFile file(stream);
    const Imf::Header& header = file.header();
    const Imath::Box2i window = header.dataWindow();
    const long long width = static_cast<long long>(window.max.x) - window.min.x + 1;
    const long long rows = static_cast<long long>(window.max.y) - window.min.y + 1;
    if (width <= 0 || rows <= 0) throw IoError(source + ": corrupt EXR: empty data window");
    image.exr_compression = ExrCompression::kOther;
    for (const ExrCodec& codec : kExrCodecs) {
      if (codec.imf == header.compression()) image.exr_compression = codec.compression;
    }
    for (auto it = header.begin(); it != header.end(); ++it) {
      if (const auto* text = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) {
        if (std::strncmp(it.name(), "skybake.", 8) == 0) image.metadata[it.name()] = text->value();
      }
    }
    // The atlas unstacks only if skybake.size agrees with the image.
    long long height = rows, depth = 1;
    auto size = image.metadata.find(kSizeKey);
    if (size != image.metadata.end()) {
      std::vector<long long> dims;
      if (!ParseSize(size->second, &dims) || dims[0] != width ||
          dims[1] * (dims.size() == 3 ? dims[2] : 1) != rows) {
        throw IoError(source + ": corrupt EXR: skybake.size '" + size->second + "' does not fit the " +
                      std::to_string(width) + "x" + std::to_string(rows) + " image");
      }
      height = dims[1];
      if (dims.size() == 3) depth = dims[2], image.is_3d = true;
    }
    bool any_half = false, any_float = false;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      const Imf::Channel& channel = it.channel();
      if (channel.xSampling != 1 || channel.ySampling != 1) {
        throw IoError(source + ": unsupported EXR: channel " + it.name() + " is subsampled");
      }
      any_half |= channel.type == Imf::HALF;
      any_float |= channel.type != Imf::HALF;
      image.channel_names.push_back(it.name());
    }
    if (image.channel_names.empty()) throw IoError(source + ": EXR file has no channels");
    // Skybake writes R, G, B, A; ChannelList iterates alphabetically, so put
    // the colour channels back in their order.
    const std::vector<std::string> rgba = {"R", "G", "B", "A"};
    std::stable_sort(image.channel_names.begin(), image.channel_names.end(), [&](const auto& a, const auto& b) {
      auto rank = [&](const std::string& n) { return std::find(rgba.begin(), rgba.end(), n) - rgba.begin(); };
      return rank(a) < rank(b);
    });
    image.pixel_type = any_half && !any_float ? PixelType::kHalf : PixelType::kFloat;
    const std::size_t channels = image.channel_names.size();
    if (static_cast<unsigned long long>(width) * rows * channels > kMaxValues) {
      throw IoError(source + ": EXR image of " + std::to_string(width) + "x" + std::to_string(rows) + "x" +
                    std::to_string(channels) + " values is larger than skybake reads");
    }
    image.width = static_cast<int>(width);
    image.height = static_cast<int>(height);
    image.depth = static_cast<int>(depth);
    image.values.assign(image.TexelCount() * channels, 0.0f);

    Imf::FrameBuffer frame;
    const std::size_t x_stride = channels * sizeof(float), y_stride = x_stride * width;
    for (std::size_t c = 0; c < channels; ++c) {
      // OpenEXR addresses pixels by absolute coordinates: offset the base.
      char* base = reinterpret_cast<char*>(image.values.data() + c) -
                   static_cast<std::ptrdiff_t>(window.min.x) * static_cast<std::ptrdiff_t>(x_stride) -
                   static_cast<std::ptrdiff_t>(window.min.y) * static_cast<std::ptrdiff_t>(y_stride);
      frame.insert(image.channel_names[c], Imf::Slice(Imf::FLOAT, base, x_stride, y_stride));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
  } catch (const IoError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw IoError(source + ": EXR image too large to read");
  } catch (const std::exception& e) {
    throw IoError(source + ": truncated or corrupt EXR file: " + OneLine(e.what()));
  }
  return image;
}

// ---------------------------------------------------------------------------
// KTX2 through formats/ktx2.h.

const std::vector<std::string> kRgba = {"R", "G", "B", "A"};

std::vector<std::uint8_t> EncodeKtx2(const TableImage& image) {
  const std::size_t channels = image.channel_names.size();
  if (channels < 3 || channels > 4 || !std::equal(image.channel_names.begin(), image.channel_names.end(), kRgba.begin())) {
    throw InputError("KTX2 tables hold channels R,G,B or R,G,B,A, not the " + std::to_string(channels) +
                     " channels of this table");
  }
  ktx2::Texture texture;
  texture.format = image.pixel_type == PixelType::kHalf ? ktx2::VkFormat::kR16G16B16A16Sfloat
                                                        : ktx2::VkFormat::kR32G32B32A32Sfloat;
  texture.width = static_cast<std::uint32_t>(image.width);
  texture.height = static_cast<std::uint32_t>(image.height);
  texture.depth = image.is_3d ? static_cast<std::uint32_t>(image.depth) : 0;
  // Alpha 0 where the table has none.
  texture.data = ktx2::PackChannels(texture.format, image.values.data(), image.TexelCount(), static_cast<int>(channels));
  texture.key_values = image.metadata;
  texture.key_values[kSizeKey] = SizeString(image.width, image.height, image.depth, image.is_3d);
  if (image.ktx2_zstd_level != 0) {
    texture.supercompression = ktx2::Supercompression::kZstd;
    texture.zstd_level = image.ktx2_zstd_level;
  }
  return ktx2::Encode(texture);
}

TableImage DecodeKtx2(const std::vector<std::uint8_t>& bytes, const std::string& source) {
  const ktx2::Texture texture = ktx2::Decode(bytes, source);
  if (ktx2::ChannelCount(texture.format) != 4) {
    throw IoError(source + ": unsupported KTX2 table: " + ktx2::FormatName(texture.format) +
                  " (skybake tables are RGBA)");
  }
  TableImage image;
  image.format = FileFormat::kKtx2;
  image.pixel_type = ktx2::BytesPerChannel(texture.format) == 2 ? PixelType::kHalf : PixelType::kFloat;
  if (texture.supercompression == ktx2::Supercompression::kZstd) image.ktx2_zstd_level = ktx2::kZstdDefaultLevel;
  image.is_3d = texture.Is3D();
  if (texture.TexelCount() * 4 > kMaxValues) {
    throw IoError(source + ": KTX2 texture larger than skybake reads");
  }
  image.width = static_cast<int>(texture.width);
  image.height = static_cast<int>(texture.height);
  image.depth = image.is_3d ? static_cast<int>(texture.depth) : 1;
  image.channel_names = kRgba;
  image.values = ktx2::UnpackFloats(texture.format, texture.data);
  image.metadata = texture.key_values;
  auto size = image.metadata.find(kSizeKey);
  if (size != image.metadata.end() &&
      size->second != SizeString(image.width, image.height, image.depth, image.is_3d)) {
    throw IoError(source + ": corrupt KTX2 table: skybake.size '" + size->second + "' disagrees with the header (" +
                  SizeString(image.width, image.height, image.depth, image.is_3d) + ")");
  }
  return image;
}

bool StartsWith(const std::vector<std::uint8_t>& bytes, const std::uint8_t* magic, std::size_t size) {
  return bytes.size() >= size && std::memcmp(bytes.data(), magic, size) == 0;
}

}  // namespace

const char* ToString(FileFormat format) { return format == FileFormat::kExr ? "exr" : "ktx2"; }
const char* ToString(PixelType type) { return type == PixelType::kHalf ? "half" : "float"; }
const char* FileExtension(FileFormat format) { return format == FileFormat::kExr ? ".exr" : ".ktx2"; }

std::optional<FileFormat> ParseFileFormat(const std::string& name) {
  if (name == "exr") return FileFormat::kExr;
  if (name == "ktx2") return FileFormat::kKtx2;
  return std::nullopt;
}

std::optional<FileFormat> FileFormatOfPath(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension == ".exr") return FileFormat::kExr;
  if (extension == ".ktx2") return FileFormat::kKtx2;
  return std::nullopt;
}

std::string TableImage::StorageName() const {
  if (format == FileFormat::kKtx2) {
    return std::string(pixel_type == PixelType::kHalf ? "VK_FORMAT_R16G16B16A16_SFLOAT"
                                                      : "VK_FORMAT_R32G32B32A32_SFLOAT") +
           (ktx2_zstd_level != 0 ? ", zstd" : "");
  }
  const ExrCodec* codec = FindExrCodec(exr_compression);
  return std::string("EXR ") + ToString(pixel_type) + " " + (codec ? codec->name : "other compression");
}

void ChooseExrCompression(TableImage* image) {
  if (image->format != FileFormat::kExr) return;
  const int rows = image->height * image->depth;
  const std::size_t row_values = std::size_t(image->width) * image->channel_names.size();
  // The rows [first, first + count) of the image, appended to `sample`.
  auto append_rows = [&](TableImage* sample, int first, int count) {
    const auto begin = image->values.begin() + std::ptrdiff_t(first * row_values);
    sample->values.insert(sample->values.end(), begin, begin + std::ptrdiff_t(count * row_values));
    sample->height += count;
  };
  // The share of the sample's stored size that each codec saves.
  auto savings = [&](TableImage sample, std::initializer_list<ExrCompression> codecs) {
    sample.exr_compression = ExrCompression::kNone;
    const double stored = double(EncodeExr(sample).size());
    std::vector<double> result;
    for (ExrCompression codec : codecs) {
      sample.exr_compression = codec;
      result.push_back(1.0 - double(EncodeExr(sample).size()) / stored);
    }
    return result;
  };
  TableImage empty;
  empty.format = FileFormat::kExr;
  empty.pixel_type = image->pixel_type;
  empty.width = image->width;
  empty.channel_names = image->channel_names;
  // RLE codes each row on its own, so single rows spread over the whole
  // image sample its saving, wherever the runs are: the Earth's single Mie
  // table saves 9.3 % in every r slice but the ground's, which saves 53 %
  // and brings the whole to 10.7 %. One row in kRleSampleShare, placed by
  // the golden ratio's multiples (which no period of the image's rows
  // aliases, as even steps would a table dark in every other row), in order.
  constexpr int kRleSampleShare = 16;
  constexpr double kGoldenRatioFraction = 0.6180339887498949;  // (sqrt(5) - 1) / 2
  const int rle_rows = (rows + kRleSampleShare - 1) / kRleSampleShare;
  std::vector<int> sampled_rows(rle_rows);
  for (int i = 0; i < rle_rows; ++i) sampled_rows[i] = int(std::fmod(0.5 + i * kGoldenRatioFraction, 1.0) * rows);
  std::sort(sampled_rows.begin(), sampled_rows.end());
  TableImage rle_sample = empty;
  for (int row : sampled_rows) append_rows(&rle_sample, row, 1);
  // ZIP codes blocks of 16 rows: kZipSampleBlocks of them, each in the
  // middle of its share of the image (the first rows, the ground and views
  // into it, are the most compressible and would speak for too much), give
  // its saving and how much more it saves than RLE on the same rows.
  constexpr int kBlockRows = 16, kZipSampleBlocks = 4;
  const int blocks = (rows + kBlockRows - 1) / kBlockRows;
  const int step = std::max(1, blocks / kZipSampleBlocks);
  TableImage zip_sample = empty;
  for (int block = step / 2; block < blocks; block += step) {
    append_rows(&zip_sample, block * kBlockRows, std::min(kBlockRows, rows - block * kBlockRows));
  }
  const double rle_saving = savings(std::move(rle_sample), {ExrCompression::kRle})[0];
  const std::vector<double> on_blocks = savings(std::move(zip_sample), {ExrCompression::kZip, ExrCompression::kRle});
  const double zip_saving = on_blocks[0], zip_over_rle = on_blocks[0] - on_blocks[1];
  const bool rle_pays = rle_saving >= kExrMinimumSaving;
  if (zip_saving >= kExrMinimumSaving && (!rle_pays || zip_over_rle >= kExrMinimumSaving)) {
    image->exr_compression = ExrCompression::kZip;
  } else {
    image->exr_compression = rle_pays ? ExrCompression::kRle : ExrCompression::kNone;
  }
}

void ChooseFileStorage(TableImage* image, int ktx2_zstd_level) {
  ChooseExrCompression(image);
  if (image->format == FileFormat::kKtx2) image->ktx2_zstd_level = ktx2_zstd_level;
}

std::vector<std::string> StoredChannels(const TableImage& image) {
  return image.format == FileFormat::kKtx2 ? kRgba : image.channel_names;
}

std::vector<std::string> MeaningfulChannels(const TableImage& image, const std::string& source) {
  auto listed = image.metadata.find(kChannelsKey);
  if (listed == image.metadata.end()) return image.channel_names;
  std::vector<std::string> names;
  const std::string& list = listed->second;
  for (std::size_t at = 0; at <= list.size();) {
    std::size_t end = list.find(',', at);
    if (end == std::string::npos) end = list.size();
    names.push_back(list.substr(at, end - at));
    at = end + 1;
  }
  for (const std::string& name : names) {
    if (std::find(image.channel_names.begin(), image.channel_names.end(), name) == image.channel_names.end()) {
      throw IoError(source + ": " + kChannelsKey + " names channel '" + name + "', which the file does not have");
    }
  }
  return names;
}

std::vector<std::uint8_t> EncodeTableImage(const TableImage& image) {
  CheckShape(image);
  return image.format == FileFormat::kExr ? EncodeExr(image) : EncodeKtx2(image);
}

TableImage DecodeTableImage(const std::vector<std::uint8_t>& bytes, const std::string& source) {
  if (bytes.empty()) throw IoError(source + ": empty file");
  if (StartsWith(bytes, kKtx2Magic, 4)) return DecodeKtx2(bytes, source);  // Decode tells a cut identifier apart
  if (StartsWith(bytes, kExrMagic, 4)) return DecodeExr(bytes, source);
  throw IoError(source + ": not an EXR or KTX2 file");
}

void WriteTableImage(const fs::path& path, const TableImage& image) {
  const std::vector<std::uint8_t> bytes = EncodeTableImage(image);
  WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

TableImage ReadTableImage(const fs::path& path) { return DecodeTableImage(ReadFileBytes(path), path.string()); }

}  // namespace skybake
