// Whole baked sets on disk (formats/lut_files.h, formats/manifest.h): both
// formats round-trip exactly (float) or to the documented rounding (half);
// the manifest lists every file with a SHA-256 that matches its bytes; the
// loader refuses missing, truncated, altered and foreign files with one-line
// IoErrors; writing is byte-reproducible across runs and thread counts.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/config.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_files.h"
#include "formats/lut_tables.h"
#include "formats/manifest.h"
#include "formats/sha256.h"
#include "test_atmospheres.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::TempDir;

BakeSettings SmallSettings(int threads, bool pack_mie = false) {
  BakeSettings s = testing::SmallBakeSettings();
  s.threads = threads;
  s.pack_single_mie_in_alpha = pack_mie;
  return s;
}

const std::vector<std::string> kTables = {"transmittance", "irradiance", "scattering", "single_mie_scattering"};

class LutFilesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { luts_ = new LutSet(Bake(LoadPreset("earth"), SmallSettings(2))); }
  static void TearDownTestSuite() { delete luts_; }
  static const LutSet& Luts() { return *luts_; }
  static LutSet* luts_;
};
LutSet* LutFilesTest::luts_ = nullptr;

bool SameBits(const LargeBuffer<float>& a, const LargeBuffer<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

void ExpectSameSet(const LutSet& loaded, const LutSet& original, bool half) {
  EXPECT_EQ(ToToml(loaded.atmosphere), ToToml(original.atmosphere));
  EXPECT_EQ(ParametersToJson(loaded.parameters), ParametersToJson(original.parameters));
  EXPECT_EQ(loaded.settings.orders, original.settings.orders);
  EXPECT_EQ(loaded.orders_used, original.orders_used);
  EXPECT_EQ(loaded.settings.ray_samples, original.settings.ray_samples);
  EXPECT_EQ(loaded.settings.pack_single_mie_in_alpha, original.settings.pack_single_mie_in_alpha);
  for (const TableDescription& table : DescribeTables(original)) {
    const glsl::Texture& a = TableTexture(loaded, table.name);
    const glsl::Texture& b = TableTexture(original, table.name);
    ASSERT_EQ(a.width, b.width) << table.name;
    ASSERT_EQ(a.height, b.height) << table.name;
    ASSERT_EQ(a.depth, b.depth) << table.name;
    LargeBuffer<float> expected = b.texels;
    if (half) {
      for (float& v : expected) v = static_cast<float>(Imath::half(v));
    }
    EXPECT_TRUE(SameBits(a.texels, expected)) << table.name;
  }
}

// The IoError message of `load` ("" if it loaded). Other exceptions fail.
template <typename F>
std::string IoErrorOf(F load) {
  try {
    load();
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

// Zstandard-supercompressed KTX2 reads back bit for bit, lists its storage
// and is smaller than the KTX2 stored as is.
TEST_F(LutFilesTest, ZstdKtx2RoundTripIsExactAndSmaller) {
  TempDir plain, zstd;
  WriteOptions options;
  options.formats = {FileFormat::kKtx2};
  const WriteReport plain_files = WriteLutSet(Luts(), plain.path(), options);
  options.ktx2_zstd_level = 5;
  const WriteReport zstd_files = WriteLutSet(Luts(), zstd.path(), options);
  ExpectSameSet(LoadLutSet(zstd.path()), Luts(), false);
  std::uint64_t plain_bytes = 0, zstd_bytes = 0;
  for (const WrittenFile& f : plain_files.files) plain_bytes += f.table.empty() ? 0 : f.bytes;
  for (const WrittenFile& f : zstd_files.files) zstd_bytes += f.table.empty() ? 0 : f.bytes;
  EXPECT_LT(zstd_bytes, plain_bytes);
  const json manifest = json::parse(testing::ReadText(zstd.path() / kManifestFileName));
  for (const json& table : manifest["tables"]) {
    for (const json& f : table["files"]) EXPECT_EQ(f["storage"], "VK_FORMAT_R32G32B32A32_SFLOAT, zstd") << f["file"];
  }
}

TEST_F(LutFilesTest, FloatRoundTripIsExactInEachFormat) {
  TempDir dir;
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    SCOPED_TRACE(ToString(format));
    ExpectSameSet(LoadLutSet(dir.path(), LoadOptions{format}), Luts(), false);
  }
}

TEST_F(LutFilesTest, HalfRoundTripRoundsEachValueOnceToNearestEven) {
  TempDir dir;
  WriteOptions options;
  options.half = true;
  const WriteReport report = WriteLutSet(Luts(), dir.path(), options);
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    SCOPED_TRACE(ToString(format));
    ExpectSameSet(LoadLutSet(dir.path(), LoadOptions{format}), Luts(), true);
  }
  // One half-error figure per table; rounding normal halves costs at most 2^-11.
  ASSERT_EQ(report.half_errors.size(), 4u);
  for (const auto& [table, error] : report.half_errors) {
    EXPECT_GT(error.measured, 0u) << table;
    EXPECT_GT(error.max_relative_error, 0.0) << table;
    EXPECT_LE(error.max_relative_error, std::ldexp(1.0, -11)) << table;
    EXPECT_EQ(error.overflowed, 0u) << table;
  }
}

TEST_F(LutFilesTest, PackedSingleMieRoundTripsAsRgba) {
  const LutSet packed = Bake(LoadPreset("earth"), SmallSettings(2, /*pack_mie=*/true));
  TempDir dir;
  WriteLutSet(packed, dir.path(), WriteOptions{});
  EXPECT_FALSE(fs::exists(dir.path() / "single_mie_scattering.exr"));
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    SCOPED_TRACE(ToString(format));
    ExpectSameSet(LoadLutSet(dir.path(), LoadOptions{format}), packed, false);
  }
  const TableImage exr = ReadTableImage(dir.path() / "scattering.exr");
  EXPECT_EQ(exr.channel_names, (std::vector<std::string>{"R", "G", "B", "A"}));
  EXPECT_EQ(exr.metadata.at(kChannelsKey), "R,G,B,A");
}

TEST_F(LutFilesTest, ManifestListsEveryFileWithMatchingChecksum) {
  TempDir dir;
  WriteOptions options;
  options.command_line = "skybake bake earth -o somewhere";
  WriteLutSet(Luts(), dir.path(), options);
  const json manifest = json::parse(ReadFileText(dir.path() / kManifestFileName));
  EXPECT_EQ(manifest["schema"], "skybake.manifest");
  EXPECT_EQ(manifest["schema_version"], 8);
  EXPECT_EQ(manifest["command"], "skybake bake earth -o somewhere");
  EXPECT_EQ(manifest["wavelengths_nm"], json::array({680.0, 550.0, 440.0}));
  EXPECT_EQ(manifest["parameters"]["scattering_mu_size"], 32);
  EXPECT_EQ(manifest["parameters"]["transmittance_is_colour"], 0);  // one wavelength per channel
  EXPECT_EQ(manifest["atmosphere"]["name"], "earth");
  EXPECT_TRUE(manifest["shaders"].is_array());
  EXPECT_TRUE(manifest["shaders"].empty());
  ASSERT_EQ(manifest["tables"].size(), kTables.size());
  std::size_t listed = 0;
  for (std::size_t t = 0; t < kTables.size(); ++t) {
    const json& table = manifest["tables"][t];
    EXPECT_EQ(table["name"], kTables[t]);
    EXPECT_EQ(table["channels"].size(), 3u);
    EXPECT_EQ(table["channels"][2]["wavelength_nm"], 440.0);
    EXPECT_FALSE(table["encoding"].get<std::string>().empty());
    EXPECT_FALSE(table["units"].get<std::string>().empty());
    EXPECT_EQ(table["axes"].size(), t < 2 ? 2u : 4u);
    ASSERT_EQ(table["files"].size(), 2u);
    for (const json& f : table["files"]) {
      const std::string file = f["file"];
      const std::vector<std::uint8_t> bytes = ReadFileBytes(dir.path() / file);
      EXPECT_EQ(f["bytes"], bytes.size()) << file;
      EXPECT_EQ(f["sha256"], Sha256Hex(bytes.data(), bytes.size())) << file;
      EXPECT_EQ(f["pixel_type"], "float");
      EXPECT_EQ(file, kTables[t] + (f["format"] == "exr" ? ".exr" : ".ktx2"));
      EXPECT_EQ(f["size"], t < 2 ? table["size"] : json::array({32, 32, 8})) << file;
      EXPECT_EQ(f["stored_channels"].size(), f["format"] == "ktx2" ? 4u : 3u) << file;
      ++listed;
    }
  }
  EXPECT_EQ(listed, 8u);
  // Nothing else in the directory: no temporary files left behind.
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos);
    ++entries;
  }
  EXPECT_EQ(entries, listed + 1);
}

TEST_F(LutFilesTest, OneFormatOnly) {
  TempDir dir;
  WriteOptions options;
  options.formats = {FileFormat::kKtx2};
  WriteLutSet(Luts(), dir.path(), options);
  EXPECT_TRUE(fs::exists(dir.path() / "scattering.ktx2"));
  EXPECT_FALSE(fs::exists(dir.path() / "scattering.exr"));
  ExpectSameSet(LoadLutSet(dir.path()), Luts(), false);
  const std::string error = IoErrorOf([&] { LoadLutSet(dir.path(), LoadOptions{FileFormat::kExr}); });
  EXPECT_NE(error.find("lists no exr file for the transmittance table"), std::string::npos) << error;
}

// Shader files (the GLSL engineer's slot): one entry in WriteOptions, listed
// with size and checksum, verified by ReadManifest's users like any file.
TEST_F(LutFilesTest, ShaderFilesAreWrittenAndListed) {
  TempDir dir;
  WriteOptions options;
  options.shaders.push_back({"atmosphere.glsl", "// runtime\nvoid main() {}\n", "GLSL runtime"});
  WriteLutSet(Luts(), dir.path(), options);
  EXPECT_EQ(ReadFileText(dir.path() / "atmosphere.glsl"), "// runtime\nvoid main() {}\n");
  const Manifest manifest = ReadManifest(dir.path());
  ASSERT_EQ(manifest.shader_files.size(), 1u);
  EXPECT_EQ(manifest.shader_files[0].file, "atmosphere.glsl");
  EXPECT_EQ(manifest.shader_files[0].sha256, Sha256Hex("// runtime\nvoid main() {}\n"));
  EXPECT_EQ(manifest.document["shaders"][0]["description"], "GLSL runtime");
  EXPECT_EQ(FindListing(dir.path() / "atmosphere.glsl")->bytes, 26u);
}

// Without a format, the loader takes KTX2 when it is complete on disk (no
// decompression) and otherwise OpenEXR.
TEST_F(LutFilesTest, LoaderPrefersCompleteKtx2ThenExr) {
  TempDir dir;
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  // A broken EXR does not matter while KTX2 is complete...
  testing::WriteText(dir.path() / "irradiance.exr", "garbage");
  ExpectSameSet(LoadLutSet(dir.path()), Luts(), false);
  EXPECT_NE(IoErrorOf([&] { LoadLutSet(dir.path(), LoadOptions{FileFormat::kExr}); }).find("irradiance.exr"),
            std::string::npos);
  // ...and with a KTX2 file gone the EXR set is read.
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  fs::remove(dir.path() / "scattering.ktx2");
  ExpectSameSet(LoadLutSet(dir.path()), Luts(), false);
}

TEST_F(LutFilesTest, DamagedFilesAreOneLineIoErrorsNamingTheFile) {
  TempDir dir;
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  const fs::path backup = dir.path() / "backup";
  fs::create_directory(backup);
  for (FileFormat format : {FileFormat::kExr, FileFormat::kKtx2}) {
    for (const std::string& table : {std::string("transmittance"), std::string("scattering")}) {
      const std::string name = table + FileExtension(format);
      const fs::path path = dir.path() / name;
      fs::copy_file(path, backup / name, fs::copy_options::overwrite_existing);
      const std::vector<std::uint8_t> good = ReadFileBytes(path);
      auto write = [&](const std::vector<std::uint8_t>& bytes) {
        WriteFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
      };
      auto expect_error = [&](const std::string& what, const std::string& expected) {
        const std::string error = IoErrorOf([&] { LoadLutSet(dir.path(), LoadOptions{format}); });
        EXPECT_NE(error.find(name), std::string::npos) << what << ": " << error;
        EXPECT_NE(error.find(expected), std::string::npos) << what << ": " << error;
        EXPECT_EQ(error.find('\n'), std::string::npos) << what << ": " << error;
      };
      fs::remove(path);
      expect_error("missing", "missing (listed in skybake.json)");
      write(std::vector<std::uint8_t>(good.begin(), good.begin() + good.size() / 2));
      expect_error("truncated", "truncated");
      for (std::size_t at : {std::size_t(5), good.size() / 2, good.size() - 1}) {
        std::vector<std::uint8_t> flipped = good;
        flipped[at] ^= 0x10;
        write(flipped);
        expect_error("bit flip at " + std::to_string(at), "checksum mismatch");
      }
      const std::string text = "hello";
      write(std::vector<std::uint8_t>(text.begin(), text.end()));
      expect_error("foreign", "truncated");  // 5 bytes where the manifest lists more
      // Another table's file in its place: its checksum differs.
      write(ReadFileBytes(dir.path() / ("irradiance" + std::string(FileExtension(format)))));
      expect_error("swapped", "");
      fs::copy_file(backup / name, path, fs::copy_options::overwrite_existing);
    }
  }
  ExpectSameSet(LoadLutSet(dir.path()), Luts(), false);  // restored
}

// With the manifest rewritten to match a damaged file, the file's own checks
// (decoder, table name, dimensions) still refuse it.
TEST_F(LutFilesTest, FileChecksBeyondTheChecksum) {
  TempDir dir;
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  auto relist = [&](const std::string& file) {
    json manifest = json::parse(ReadFileText(dir.path() / kManifestFileName));
    const std::vector<std::uint8_t> bytes = ReadFileBytes(dir.path() / file);
    for (json& table : manifest["tables"]) {
      for (json& f : table["files"]) {
        if (f["file"] == file) f["bytes"] = bytes.size(), f["sha256"] = Sha256Hex(bytes.data(), bytes.size());
      }
    }
    WriteFileAtomically(dir.path() / kManifestFileName, manifest.dump(2));
  };
  fs::copy_file(dir.path() / "irradiance.ktx2", dir.path() / "transmittance.ktx2",
                fs::copy_options::overwrite_existing);
  relist("transmittance.ktx2");
  EXPECT_NE(IoErrorOf([&] { LoadLutSet(dir.path(), LoadOptions{FileFormat::kKtx2}); })
                .find("transmittance.ktx2: holds the irradiance table, expected transmittance"),
            std::string::npos);
  testing::WriteText(dir.path() / "irradiance.exr", "not an image at all");
  relist("irradiance.exr");
  EXPECT_NE(IoErrorOf([&] { LoadLutSet(dir.path(), LoadOptions{FileFormat::kExr}); })
                .find("irradiance.exr: not an EXR or KTX2 file"),
            std::string::npos);
}

TEST_F(LutFilesTest, ManifestErrors) {
  TempDir dir;
  EXPECT_NE(IoErrorOf([&] { LoadLutSet(dir.path()); }).find("no manifest"), std::string::npos);
  WriteLutSet(Luts(), dir.path(), WriteOptions{});
  const fs::path path = dir.path() / kManifestFileName;
  const json good = json::parse(ReadFileText(path));
  auto error_with = [&](const std::function<void(json&)>& edit) {
    json manifest = good;
    edit(manifest);
    WriteFileAtomically(path, manifest.dump(2));
    return IoErrorOf([&] { LoadLutSet(dir.path()); });
  };
  EXPECT_NE(error_with([](json& m) { m["schema_version"] = 1; }).find("schema version 1, this skybake reads version 8"),
            std::string::npos);
  EXPECT_NE(error_with([](json& m) { m["schema"] = "other"; }).find("not a skybake manifest"), std::string::npos);
  EXPECT_NE(error_with([](json& m) { m["tables"][0]["files"][0]["file"] = "../transmittance.exr"; })
                .find("must be a plain name"),
            std::string::npos);
  EXPECT_NE(error_with([](json& m) { m["parameters"]["scattering_mu_size"] = 31; }).find("must be even"),
            std::string::npos);
  EXPECT_NE(error_with([](json& m) { m.erase("bake"); }).find("malformed manifest"), std::string::npos);
  WriteFileAtomically(path, "{ not json");
  const std::string error = IoErrorOf([&] { LoadLutSet(dir.path()); });
  EXPECT_NE(error.find("malformed manifest"), std::string::npos);
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
}

// Table files hold nothing but what the atmosphere and settings determine:
// writing twice, or after baking with a different thread count, gives the
// same bytes; manifests differ only where the command line does.
TEST_F(LutFilesTest, FilesAreByteIdenticalAcrossRunsAndThreadCounts) {
  const LutSet single_thread = Bake(LoadPreset("earth"), SmallSettings(1));
  for (bool half : {false, true}) {
    TempDir a, b, c;
    WriteOptions options;
    options.half = half;
    options.command_line = "first";
    WriteLutSet(Luts(), a.path(), options);
    WriteLutSet(Luts(), b.path(), options);
    options.command_line = "second";
    WriteLutSet(single_thread, c.path(), options);
    for (const std::string& table : kTables) {
      for (const char* extension : {".exr", ".ktx2"}) {
        const std::string file = table + extension;
        const auto bytes = ReadFileBytes(a.path() / file);
        EXPECT_TRUE(bytes == ReadFileBytes(b.path() / file)) << file << " half=" << half;
        EXPECT_TRUE(bytes == ReadFileBytes(c.path() / file)) << file << " half=" << half << " (threads 2 vs 1)";
      }
    }
    EXPECT_EQ(ReadFileText(a.path() / kManifestFileName), ReadFileText(b.path() / kManifestFileName));
    json manifest_c = json::parse(ReadFileText(c.path() / kManifestFileName));
    manifest_c["command"] = "first";
    EXPECT_EQ(manifest_c, json::parse(ReadFileText(a.path() / kManifestFileName)));
  }
}

}  // namespace
}  // namespace skybake
