// formats/table_file.h (one table in EXR or KTX2, in memory) and
// formats/table_stats.h: exact round trips in every format, pixel type and
// shape; the EXR atlas read back by an independent reader (OpenImageIO);
// damaged and foreign files refused with one-line IoErrors; half error
// figures checked against hand-computed values.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <OpenImageIO/imagebuf.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/file_io.h"
#include "formats/ktx2.h"
#include "formats/table_file.h"
#include "formats/table_stats.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;
using testing::TempDir;

// Values across the range a table holds: exact small fractions, values that
// need rounding in half, tiny (subnormal in half) values and zeros.
TableImage MakeImage(FileFormat format, PixelType type, int w, int h, int d, bool is_3d, int channels) {
  TableImage image;
  image.format = format;
  image.pixel_type = type;
  image.width = w, image.height = h, image.depth = d, image.is_3d = is_3d;
  const char* names[4] = {"R", "G", "B", "A"};
  for (int c = 0; c < channels; ++c) image.channel_names.push_back(names[c]);
  std::mt19937 random(1234);
  std::uniform_real_distribution<float> exponent(-30.0f, 10.0f);
  image.values.resize(image.TexelCount() * channels);
  for (std::size_t i = 0; i < image.values.size(); ++i) {
    image.values[i] = i % 7 == 0 ? 0.0f : std::exp2(exponent(random)) * (i % 5 == 0 ? -1.0f : 1.0f);
  }
  image.metadata = {{kTableKey, "scattering"}, {"skybake.note", "caf\xC3\xA9"}, {kChannelsKey, "R,G,B"}};
  return image;
}

float Stored(PixelType type, float v) { return type == PixelType::kHalf ? static_cast<float>(Imath::half(v)) : v; }

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// Runs DecodeTableImage; returns the IoError message, "" if it decoded.
// Any other exception fails the test.
std::string DecodeError(const Bytes& bytes, const std::string& source = "table.bin") {
  try {
    DecodeTableImage(bytes, source);
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

TEST(TableFile, FormatNamesAndExtensions) {
  EXPECT_EQ(FileFormatOfPath("a/b/scattering.ktx2"), FileFormat::kKtx2);
  EXPECT_EQ(FileFormatOfPath("T.EXR"), FileFormat::kExr);
  EXPECT_EQ(FileFormatOfPath("x.png"), std::nullopt);
  EXPECT_EQ(ParseFileFormat("ktx2"), FileFormat::kKtx2);
  EXPECT_EQ(ParseFileFormat("KTX"), std::nullopt);
  EXPECT_STREQ(FileExtension(FileFormat::kExr), ".exr");
}

TEST(TableFile, RoundTripsEveryFormatPixelTypeAndShape) {
  struct Shape {
    int w, h, d;
    bool is_3d;
    int channels;
  };
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    for (PixelType type : {PixelType::kFloat, PixelType::kHalf}) {
      for (Shape s : {Shape{5, 3, 1, false, 3}, Shape{4, 3, 2, true, 3}, Shape{6, 2, 3, true, 4}, Shape{3, 2, 1, true, 4}}) {
        SCOPED_TRACE(std::string(ToString(format)) + " " + ToString(type) + " " + std::to_string(s.w) + "x" +
                     std::to_string(s.h) + "x" + std::to_string(s.d) + (s.is_3d ? " 3D" : " 2D"));
        const TableImage in = MakeImage(format, type, s.w, s.h, s.d, s.is_3d, s.channels);
        const TableImage out = DecodeTableImage(EncodeTableImage(in), "t");
        EXPECT_EQ(out.format, format);
        EXPECT_EQ(out.pixel_type, type);
        EXPECT_EQ(out.width, s.w);
        EXPECT_EQ(out.height, s.h);
        EXPECT_EQ(out.depth, s.d);
        EXPECT_EQ(out.is_3d, s.is_3d);
        // KTX2 stores RGBA: an RGB table comes back with an alpha of zeros.
        const int stored = format == FileFormat::kKtx2 ? 4 : s.channels;
        ASSERT_EQ(out.channel_names.size(), static_cast<std::size_t>(stored));
        for (std::size_t i = 0; i < in.TexelCount(); ++i) {
          for (int c = 0; c < stored; ++c) {
            const float expected = c < s.channels ? Stored(type, in.values[i * s.channels + c]) : 0.0f;
            ASSERT_TRUE(SameBits(out.values[i * stored + c], expected))
                << "texel " << i << " channel " << c << ": " << out.values[i * stored + c] << " vs " << expected;
          }
        }
        for (const auto& [key, value] : in.metadata) EXPECT_EQ(out.metadata.at(key), value) << key;
        const std::string size = std::to_string(s.w) + "x" + std::to_string(s.h) + (s.is_3d ? "x" + std::to_string(s.d) : "");
        EXPECT_EQ(out.metadata.at(kSizeKey), size);
        EXPECT_EQ(out.metadata.count(format == FileFormat::kKtx2 ? "KTXwriter" : kExrGeneratorKey), 1u);
      }
    }
  }
}

TEST(TableFile, EncodingIsDeterministic) {
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    const TableImage image = MakeImage(format, PixelType::kFloat, 16, 8, 4, true, 3);
    EXPECT_EQ(EncodeTableImage(image), EncodeTableImage(image)) << ToString(format);
  }
}

// OpenImageIO is an independent EXR reader: it must see the documented atlas
// (width x height*depth, row = z * height + y) and the metadata.
TEST(TableFile, ExrAtlasAsAnIndependentReaderSeesIt) {
  TempDir dir;
  const TableImage image = MakeImage(FileFormat::kExr, PixelType::kFloat, 4, 3, 5, true, 3);
  WriteTableImage(dir.path() / "atlas.exr", image);
  OIIO::ImageBuf buffer((dir.path() / "atlas.exr").string());
  ASSERT_TRUE(buffer.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << buffer.geterror();
  const OIIO::ImageSpec& spec = buffer.spec();
  EXPECT_EQ(spec.width, 4);
  EXPECT_EQ(spec.height, 15);
  ASSERT_EQ(spec.nchannels, 3);
  EXPECT_EQ(spec.channelnames[0], "R");
  EXPECT_EQ(spec.channelnames[2], "B");
  EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(spec.get_string_attribute("skybake.size"), "4x3x5");
  EXPECT_EQ(spec.get_string_attribute("skybake.table"), "scattering");
  EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
  for (int z = 0; z < 5; ++z) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 4; ++x) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t texel = (std::size_t(z) * 3 + y) * 4 + x;
          ASSERT_EQ(buffer.getchannel(x, z * 3 + y, 0, c), image.values[texel * 3 + c]) << x << "," << y << "," << z;
        }
      }
    }
  }
}

// The fastest codec that saves at least a tenth: a table dark in half of
// its rows (runs of zero bytes, as in the shadowed texels of a low sun)
// and random elsewhere is stored RLE; one that repeats a pattern of random
// values (no runs, but repeats ZIP finds) ZIP, and so is one dark in half
// of its rows and repeating in the others (ZIP saves far more than RLE);
// one of random mantissas uncompressed; one random but for its first depth
// slice of zeros RLE, as RLE saves that eighth of the image (the Earth's
// single Mie table saves most in its ground slice) though none of ZIP's
// sampled blocks lies in it. All read back bit for bit, an independent
// reader (OpenImageIO) sees the codec, and the storage name says which.
TEST(TableFile, ExrIsCompressedOnlyWhereItPays) {
  TempDir dir;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(1.0f, 2.0f);
  TableImage dark = MakeImage(FileFormat::kExr, PixelType::kFloat, 64, 32, 8, true, 3);
  for (std::size_t i = 0; i < dark.values.size(); ++i) dark.values[i] = i / (3 * 64) % 2 == 0 ? 0.0f : uniform(random);
  TableImage repeating = MakeImage(FileFormat::kExr, PixelType::kFloat, 64, 32, 8, true, 3);
  std::vector<float> pattern(97);
  for (float& v : pattern) v = uniform(random);
  for (std::size_t i = 0; i < repeating.values.size(); ++i) repeating.values[i] = pattern[i % pattern.size()];
  TableImage dark_repeating = repeating;
  for (std::size_t i = 0; i < dark_repeating.values.size(); ++i) {
    if (i / (3 * 64) % 2 == 0) dark_repeating.values[i] = 0.0f;
  }
  TableImage noisy = MakeImage(FileFormat::kExr, PixelType::kFloat, 64, 32, 8, true, 3);
  for (float& v : noisy.values) v = uniform(random);
  TableImage dark_ground = noisy;
  for (std::size_t i = 0; i < dark_ground.values.size() / 8; ++i) dark_ground.values[i] = 0.0f;
  struct Case {
    TableImage* image;
    const char* file;
    ExrCompression expected;
    const char* oiio_name;
    const char* storage;
  };
  for (const Case& c : {Case{&dark, "dark", ExrCompression::kRle, "rle", "EXR float RLE"},
                        Case{&repeating, "repeating", ExrCompression::kZip, "zip", "EXR float ZIP"},
                        Case{&dark_repeating, "dark_repeating", ExrCompression::kZip, "zip", "EXR float ZIP"},
                        Case{&noisy, "noisy", ExrCompression::kNone, "none", "EXR float uncompressed"},
                        Case{&dark_ground, "dark_ground", ExrCompression::kRle, "rle", "EXR float RLE"}}) {
    ChooseExrCompression(c.image);
    EXPECT_EQ(c.image->exr_compression, c.expected) << c.file;
    EXPECT_EQ(c.image->StorageName(), c.storage);
    const fs::path path = dir.path() / (std::string(c.file) + ".exr");
    WriteTableImage(path, *c.image);
    OIIO::ImageBuf buffer(path.string());
    ASSERT_TRUE(buffer.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << buffer.geterror();
    EXPECT_EQ(buffer.spec().get_string_attribute("compression"), c.oiio_name);
    const TableImage back = DecodeTableImage(ReadFileBytes(path), path.string());
    EXPECT_EQ(back.exr_compression, c.expected);
    ASSERT_EQ(back.values.size(), c.image->values.size());
    for (std::size_t i = 0; i < back.values.size(); ++i) ASSERT_TRUE(SameBits(back.values[i], c.image->values[i])) << i;
  }
  // The dark and repeating images shrink; the noisy one is stored at its raw size.
  EXPECT_LT(fs::file_size(dir.path() / "dark.exr"), 0.6 * dark.values.size() * 4);
  EXPECT_LT(fs::file_size(dir.path() / "repeating.exr"), 0.5 * repeating.values.size() * 4);
  EXPECT_LT(fs::file_size(dir.path() / "dark_repeating.exr"), 0.3 * dark_repeating.values.size() * 4);
  EXPECT_GE(fs::file_size(dir.path() / "noisy.exr"), noisy.values.size() * 4);
}

// KTX2 3D tables are real 3D textures (pixelDepth = depth), 2D ones have 0.
TEST(TableFile, Ktx2DepthInTheHeader) {
  for (bool is_3d : {false, true}) {
    const TableImage image = MakeImage(FileFormat::kKtx2, PixelType::kHalf, 4, 3, is_3d ? 5 : 1, is_3d, 3);
    const ktx2::Texture texture = ktx2::Decode(EncodeTableImage(image), "t.ktx2");
    EXPECT_EQ(texture.depth, is_3d ? 5u : 0u);
    EXPECT_EQ(texture.format, ktx2::VkFormat::kR16G16B16A16Sfloat);
    EXPECT_EQ(texture.key_values.at("KTXorientation"), is_3d ? "rdi" : "rd");
  }
}

TEST(TableFile, RefusesForeignAndEmptyFiles) {
  EXPECT_EQ(DecodeError({}), "table.bin: empty file");
  const std::string text = "not a table\n";
  EXPECT_EQ(DecodeError(Bytes(text.begin(), text.end())), "table.bin: not an EXR or KTX2 file");
  const Bytes png = {0x89, 'P', 'N', 'G', 0x0D, 0x0A, 0x1A, 0x0A, 0, 0, 0, 13};
  EXPECT_EQ(DecodeError(png), "table.bin: not an EXR or KTX2 file");
  // A KTX 1.1 file is named as such by the KTX2 reader.
  const Bytes ktx1 = {0xAB, 'K', 'T', 'X', ' ', '1', '1', 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
  EXPECT_NE(DecodeError(ktx1).find("KTX 1.1"), std::string::npos);
}

TEST(TableFile, KtxChannelsMustBeRgbOrRgba) {
  TableImage image = MakeImage(FileFormat::kKtx2, PixelType::kFloat, 2, 2, 1, false, 3);
  image.channel_names = {"X", "Y", "Z"};
  EXPECT_THROW(EncodeTableImage(image), InputError);
  image.values.pop_back();
  image.channel_names = {"R", "G", "B"};
  EXPECT_THROW(EncodeTableImage(image), InternalError);  // values do not fit the size
}

// Every truncation of a valid file is refused with a one-line IoError that
// names the file; no crash, no other exception.
TEST(TableFile, EveryTruncationIsAOneLineIoError) {
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    for (PixelType type : {PixelType::kFloat, PixelType::kHalf}) {
      const Bytes bytes = EncodeTableImage(MakeImage(format, type, 8, 4, 3, true, 3));
      const std::size_t step = std::max<std::size_t>(1, bytes.size() / 400);
      for (std::size_t length = 0; length < bytes.size(); length += (length < 128 ? 1 : step)) {
        const std::string error = DecodeError(Bytes(bytes.begin(), bytes.begin() + length), "cut.bin");
        ASSERT_FALSE(error.empty()) << ToString(format) << " cut to " << length << " of " << bytes.size() << " bytes";
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
        EXPECT_EQ(error.rfind("cut.bin: ", 0), 0u) << error;
      }
    }
  }
}

// Flipped bits: in structure they must be refused; in KTX2 texel data they
// cannot be seen without a checksum (the manifest's job, tested with the
// loader), so here the requirement is only: an IoError or a clean decode.
TEST(TableFile, FlippedBitsNeverCrash) {
  std::mt19937 random(99);
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    const Bytes bytes = EncodeTableImage(MakeImage(format, PixelType::kFloat, 8, 4, 3, true, 3));
    int refused = 0;
    const int trials = 600;
    for (int trial = 0; trial < trials; ++trial) {
      Bytes flipped = bytes;
      const std::size_t at = trial < 200 ? trial % bytes.size() : random() % bytes.size();
      flipped[at] ^= static_cast<std::uint8_t>(1u << (random() % 8));
      const std::string error = DecodeError(flipped, "flip.bin");
      if (!error.empty()) {
        ++refused;
        EXPECT_EQ(error.find('\n'), std::string::npos) << error;
      }
    }
    // The first 200 trials flip header bytes, which both formats check.
    EXPECT_GT(refused, 100) << ToString(format);
  }
}

TEST(TableStats, CountsNanAndInfAndRangesFiniteValues) {
  TableImage image = MakeImage(FileFormat::kKtx2, PixelType::kFloat, 2, 2, 1, false, 3);
  // Texels (R, G, B): (1, -2, NaN), (3, 0, Inf), (-Inf, 5, NaN), (0.5, 7, 1).
  image.values = {1, -2, NAN, 3, 0, INFINITY, -INFINITY, 5, NAN, 0.5f, 7, 1};
  const std::vector<ChannelStats> stats = ComputeChannelStats(image);
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_EQ(stats[0].name, "R");
  EXPECT_EQ(stats[0].finite, 3u);
  EXPECT_EQ(stats[0].inf, 1u);
  EXPECT_EQ(stats[0].nan, 0u);
  EXPECT_EQ(stats[0].min, 0.5);
  EXPECT_EQ(stats[0].max, 3.0);
  EXPECT_EQ(stats[1].finite, 4u);
  EXPECT_EQ(stats[1].min, -2.0);
  EXPECT_EQ(stats[1].max, 7.0);
  EXPECT_EQ(stats[2].nan, 2u);
  EXPECT_EQ(stats[2].inf, 1u);
  EXPECT_EQ(stats[2].finite, 1u);
  EXPECT_EQ(stats[2].min, 1.0);
  EXPECT_EQ(stats[2].max, 1.0);
}

TEST(TableStats, HalfErrorOfHandPickedValues) {
  // 1 + 2^-11 lies halfway between the halves 1 and 1 + 2^-10 and rounds to
  // the even one, 1: the largest relative rounding error a normal half makes.
  const float tie = 1.0f + std::ldexp(1.0f, -11);
  const std::vector<float> values = {tie, 3.0f, 1e-6f, 1e-9f, 70000.0f, NAN, 0.0f, -0.25f};
  const HalfError e = MeasureHalfError(values.data(), values.size());
  EXPECT_EQ(e.floor, std::ldexp(1.0, -14));
  EXPECT_EQ(e.measured, 3u);  // tie, 3, -0.25
  EXPECT_DOUBLE_EQ(e.max_relative_error, std::ldexp(1.0, -11) / (1.0 + std::ldexp(1.0, -11)));
  EXPECT_EQ(e.worst_value, tie);
  EXPECT_EQ(e.below_floor, 2u);        // 1e-6 and 1e-9
  EXPECT_EQ(e.flushed_to_zero, 1u);    // 1e-9 < 2^-25 rounds to 0
  EXPECT_LE(e.max_absolute_error_below_floor, std::ldexp(1.0, -25));  // half a subnormal step
  EXPECT_GT(e.max_absolute_error_below_floor, 0.0);
  EXPECT_EQ(e.overflowed, 1u);  // 70000 > 65504

  // A lower floor takes in 1e-6, a subnormal half: 17 * 2^-24 = 1.0133e-6.
  const HalfError low = MeasureHalfError(values.data(), values.size(), 1e-7);
  EXPECT_EQ(low.measured, 4u);
  EXPECT_NEAR(low.max_relative_error, (17.0 * std::ldexp(1.0, -24) - double(1e-6f)) / double(1e-6f), 1e-12);
  EXPECT_EQ(low.worst_value, 1e-6f);
}

}  // namespace
}  // namespace skybake
