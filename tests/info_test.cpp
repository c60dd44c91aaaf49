// `skybake info`, `skybake convert` and `bake --format` end to end: what a
// real bake writes, described and checked; damaged files give exit code 3 and
// one line; conversions keep metadata and report the half error; re-bakes are
// byte-identical in both formats whatever the thread count.
#include <gtest/gtest.h>

#include <Imath/half.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "formats/manifest.h"
#include "formats/table_file.h"
#include "test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::Lines;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;

const std::string& kSmallBake = testing::kSmallBakeOptions;

const std::vector<std::string> kTables = {"transmittance", "irradiance", "scattering", "single_mie_scattering"};

class BakedSetTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir;
    ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(Lut()) + kSmallBake, *dir_), 0);
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path Lut() { return dir_->path() / "earth"; }
  // A private copy of the baked set to damage.
  static fs::path Copy(const TempDir& into) {
    fs::copy(Lut(), into.path() / "earth", fs::copy_options::recursive);
    return into.path() / "earth";
  }
  static TempDir* dir_;
};
TempDir* BakedSetTest::dir_ = nullptr;

void FlipByte(const fs::path& path, std::size_t at) {
  std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  bytes.at(at) ^= 0x04;
  testing::WriteText(path, std::string(bytes.begin(), bytes.end()));
}

void Truncate(const fs::path& path, std::size_t length) {
  const std::string text = ReadText(path);
  testing::WriteText(path, text.substr(0, length));
}

TEST_F(BakedSetTest, InfoDescribesEveryFileOfABakedSet) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " info " + ShellQuote(Lut()), dir, &out, &err), 0) << err;
  EXPECT_NE(out.find("8 table files, 11 shader files; every checksum matches"), std::string::npos) << out;
  for (const std::string& table : kTables) {
    EXPECT_NE(out.find(table + ".exr"), std::string::npos) << table;
    EXPECT_NE(out.find(table + ".ktx2"), std::string::npos) << table;
  }
  EXPECT_NE(out.find("VK_FORMAT_R32G32B32A32_SFLOAT, 3D 32x32x8"), std::string::npos) << out;
  EXPECT_NE(out.find("skybake.table = single_mie_scattering"), std::string::npos) << out;

  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(Lut()), dir, &out, &err), 0) << err;
  const json report = json::parse(out);
  EXPECT_EQ(report["schema_version"], 8);
  ASSERT_EQ(report["files"].size(), 8u);
  for (const json& f : report["files"]) {
    SCOPED_TRACE(f["file"].get<std::string>());
    EXPECT_EQ(f["manifest"], "checksum matches skybake.json");
    EXPECT_EQ(f["metadata"]["skybake.table"], f["table"]);
    EXPECT_EQ(f["metadata"]["skybake.wavelengths_nm"], "680,550,440");
    EXPECT_EQ(f["channels"].size(), f["format"] == "ktx2" ? 4u : 3u);
    for (const json& c : f["channels"]) {
      // A bake writes finite, non-negative values only.
      EXPECT_EQ(c["nan"], 0);
      EXPECT_EQ(c["inf"], 0);
      EXPECT_GE(c["min"].get<double>(), 0.0);
      if (!c["padding"].get<bool>()) {
        EXPECT_GT(c["max"].get<double>(), 0.0);
      }
    }
  }
}

TEST_F(BakedSetTest, InfoOnOneFileChecksItAgainstTheManifest) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(Lut() / "scattering.ktx2"), dir, &out, &err), 0)
      << err;
  json report = json::parse(out);
  EXPECT_EQ(report["size"], json::array({32, 32, 8}));
  EXPECT_EQ(report["dimensions"], 3);
  EXPECT_EQ(report["manifest"], "checksum matches skybake.json");
  EXPECT_EQ(report["metadata"]["KTXorientation"], "rdi");
  // Away from its manifest, a file is described without the check.
  fs::copy_file(Lut() / "irradiance.exr", dir.path() / "irradiance.exr");
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(dir.path() / "irradiance.exr"), dir, &out, &err), 0)
      << err;
  report = json::parse(out);
  EXPECT_EQ(report["manifest"], "not listed in a manifest");
  EXPECT_EQ(report["size"], json::array({16, 4}));
  EXPECT_EQ(report["pixel_type"], "float");
}

// --plot draws the set's table slices (SVG and PNG) and lists them; it needs
// a baked directory, not one file.
TEST_F(BakedSetTest, InfoPlotsTableSlicesOfABakedSet) {
  TempDir dir;
  std::string out, err;
  const fs::path plots = dir.path() / "plots";
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(Lut()) + " --plot " + ShellQuote(plots), dir, &out,
                       &err),
            0)
      << err;
  json report = json::parse(out);
  ASSERT_EQ(report["plots"].size(), 8u) << report["plots"];
  for (const char* stem : {"lut_transmittance", "lut_sky_radiance", "lut_irradiance", "lut_sunset"}) {
    for (const char* extension : {".svg", ".png"}) {
      const fs::path file = plots / (std::string(stem) + extension);
      ASSERT_TRUE(fs::exists(file)) << file;
      EXPECT_GT(fs::file_size(file), 1000u) << file;
    }
    EXPECT_NE(ReadText(plots / (std::string(stem) + ".svg")).find("<polyline"), std::string::npos) << stem;
  }
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(Lut() / "irradiance.exr") + " --plot " + ShellQuote(plots),
                       dir, &out, &err),
            1);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
}

// NaN and Inf counts from a file that holds some.
TEST_F(BakedSetTest, InfoCountsNanAndInf) {
  TempDir dir;
  TableImage image;
  image.format = FileFormat::kExr;
  image.width = 3, image.height = 1;
  image.channel_names = {"R", "G", "B"};
  image.values = {1, NAN, 2, INFINITY, NAN, 3, -INFINITY, 4, 5};
  WriteTableImage(dir.path() / "bad.exr", image);
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " info --json " + ShellQuote(dir.path() / "bad.exr"), dir, &out, &err), 0) << err;
  const json report = json::parse(out);
  EXPECT_EQ(report["channels"][0]["inf"], 2);
  EXPECT_EQ(report["channels"][0]["finite"], 1);
  EXPECT_EQ(report["channels"][1]["nan"], 2);
  EXPECT_EQ(report["channels"][1]["min"], 4.0);
  EXPECT_EQ(report["channels"][2]["min"], 2.0);
  EXPECT_EQ(report["channels"][2]["max"], 5.0);
}

// Damaged files: exit code 3 and one line naming the file, from `info` on
// the file and on its directory and from `eval` (which loads through the
// manifest); also for copies that no manifest protects. (Every damage to
// every table file is covered in-process by lut_files_test; each run of the
// executable costs here.)
TEST_F(BakedSetTest, DamagedFilesAreExitCode3AndOneLine) {
  const std::vector<std::pair<std::string, std::function<void(const fs::path&)>>> damages = {
      {"truncated", [](const fs::path& p) { Truncate(p, fs::file_size(p) / 3); }},
      {"bit flip in the data", [](const fs::path& p) { FlipByte(p, fs::file_size(p) - 7); }},
      {"bit flip in the header", [](const fs::path& p) { FlipByte(p, 20); }},
      {"foreign", [](const fs::path& p) { testing::WriteText(p, "<html>not a table</html>"); }},
  };
  const std::vector<std::string> messages = {"truncated", "checksum mismatch", "checksum mismatch", "truncated"};
  testing::WriteText(dir_->path() / "q.csv", "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,0,0\n");
  const std::string eval_args = " --in " + ShellQuote(dir_->path() / "q.csv");
  for (const char* file : {"scattering.exr", "scattering.ktx2"}) {
    for (std::size_t d = 0; d < damages.size(); ++d) {
      SCOPED_TRACE(std::string(file) + ": " + damages[d].first);
      TempDir dir;
      const fs::path lut = Copy(dir);
      damages[d].second(lut / file);
      std::string err;
      EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(lut / file), dir, nullptr, &err), 3);
      ASSERT_EQ(Lines(err).size(), 1u) << err;
      EXPECT_NE(err.find(file), std::string::npos) << err;
      EXPECT_NE(err.find(messages[d]), std::string::npos) << err;
      if (d != 1) continue;
      EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(lut), dir, nullptr, &err), 3);
      EXPECT_EQ(Lines(err).size(), 1u) << err;
      EXPECT_NE(err.find(file), std::string::npos) << err;
      // eval loads KTX2 when it is complete; drop it to make eval read EXR.
      if (std::string(file).find(".exr") != std::string::npos) fs::remove(lut / "irradiance.ktx2");
      EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(lut) + eval_args, dir, nullptr, &err), 3);
      EXPECT_EQ(Lines(err).size(), 1u) << err;
      EXPECT_NE(err.find(file), std::string::npos) << err;
    }
  }
  {
    // A listed file that is missing: info on the directory names it; eval
    // falls back to the complete EXR set.
    TempDir dir;
    const fs::path lut = Copy(dir);
    fs::remove(lut / "scattering.ktx2");
    std::string err;
    EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(lut), dir, nullptr, &err), 3);
    EXPECT_EQ(Lines(err).size(), 1u) << err;
    EXPECT_NE(err.find("scattering.ktx2: missing"), std::string::npos) << err;
    EXPECT_EQ(RunCommand(Skybake() + " eval " + ShellQuote(lut) + eval_args, dir, nullptr, &err), 0) << err;
  }
  // Without a manifest the files' own structure is all there is to check.
  for (const char* file : {"scattering.exr", "scattering.ktx2"}) {
    TempDir dir;
    const fs::path alone = dir.path() / file;
    for (const auto& [what, damage] : std::vector<std::pair<std::string, std::function<void()>>>{
             {"truncated", [&] { Truncate(alone, fs::file_size(alone) / 2); }},
             {"header flip", [&] { FlipByte(alone, 13); }},
             {"foreign", [&] { testing::WriteText(alone, "GIF89a"); }},
             {"empty", [&] { testing::WriteText(alone, ""); }}}) {
      SCOPED_TRACE(std::string(file) + ": " + what);
      fs::copy_file(Lut() / file, alone, fs::copy_options::overwrite_existing);
      damage();
      std::string err;
      EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(alone), dir, nullptr, &err), 3);
      EXPECT_EQ(Lines(err).size(), 1u) << err;
      EXPECT_NE(err.find(file), std::string::npos) << err;
    }
  }
  std::string err;
  TempDir dir;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(dir.path() / "nothing.exr"), dir, nullptr, &err), 3);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
  EXPECT_EQ(RunCommand(Skybake() + " info " + ShellQuote(dir.path()), dir, nullptr, &err), 3);  // no manifest
  EXPECT_NE(err.find("no manifest"), std::string::npos) << err;
}

TEST_F(BakedSetTest, ConvertBetweenFormatsAndPixelTypes) {
  TempDir dir;
  const fs::path half_ktx2 = dir.path() / "s_half.ktx2", back_exr = dir.path() / "s.exr";
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " convert --json --half " + ShellQuote(Lut() / "scattering.exr") + " " +
                           ShellQuote(half_ktx2),
                       dir, &out, &err), 0)
      << err;
  const json report = json::parse(out);
  EXPECT_EQ(report["to"]["format"], "ktx2");
  EXPECT_EQ(report["to"]["pixel_type"], "half");
  EXPECT_EQ(report["channels"], json::array({"R", "G", "B"}));
  const json& e = report["half_error"];
  EXPECT_EQ(e["floor"], std::ldexp(1.0, -14));
  EXPECT_GT(e["measured"].get<std::size_t>(), 10000u);
  EXPECT_GT(e["max_relative_error"].get<double>(), 0.0);
  EXPECT_LE(e["max_relative_error"].get<double>(), std::ldexp(1.0, -11));
  EXPECT_EQ(e["overflowed"], 0);

  // Back to EXR (half stays half; the KTX2 alpha padding is dropped).
  ASSERT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(half_ktx2) + " " + ShellQuote(back_exr), dir, &out, &err), 0)
      << err;
  EXPECT_NE(err.find("lossless"), std::string::npos) << err;  // the summary goes to stderr
  const TableImage original = ReadTableImage(Lut() / "scattering.exr");
  const TableImage converted = ReadTableImage(back_exr);
  EXPECT_EQ(converted.format, FileFormat::kExr);
  EXPECT_EQ(converted.pixel_type, PixelType::kHalf);
  EXPECT_EQ(converted.channel_names, original.channel_names);
  EXPECT_TRUE(converted.is_3d);
  EXPECT_EQ(converted.depth, 8);
  ASSERT_EQ(converted.values.size(), original.values.size());
  for (std::size_t i = 0; i < original.values.size(); ++i) {
    ASSERT_EQ(converted.values[i], static_cast<float>(Imath::half(original.values[i]))) << i;
  }
  for (const char* key : {kTableKey, kEncodingKey, kUnitsKey, kWavelengthsKey, kParametersKey, kLayoutKey,
                          kChannelsKey, kAtmosphereKey}) {
    EXPECT_EQ(converted.metadata.at(key), original.metadata.at(key)) << key;
  }
  // A float EXR -> float KTX2 -> float EXR round trip is exact, and the
  // EXR is byte-identical to the baked one (same encoder, same metadata).
  ASSERT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(Lut() / "irradiance.exr") + " " +
                           ShellQuote(dir.path() / "i.ktx2"), dir), 0);
  ASSERT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(dir.path() / "i.ktx2") + " " +
                           ShellQuote(dir.path() / "i.exr"), dir), 0);
  EXPECT_TRUE(ReadFileBytes(dir.path() / "i.exr") == ReadFileBytes(Lut() / "irradiance.exr"));
  EXPECT_TRUE(ReadFileBytes(dir.path() / "i.ktx2") == ReadFileBytes(Lut() / "irradiance.ktx2"));
}

TEST_F(BakedSetTest, ConvertErrors) {
  TempDir dir;
  std::string err;
  const std::string in = ShellQuote(Lut() / "irradiance.exr");
  EXPECT_EQ(RunCommand(Skybake() + " convert " + in + " " + ShellQuote(dir.path() / "x.png"), dir, nullptr, &err), 1);
  EXPECT_NE(err.find(".exr or .ktx2"), std::string::npos) << err;
  EXPECT_EQ(RunCommand(Skybake() + " convert --half --float " + in + " " + ShellQuote(dir.path() / "x.exr"), dir), 1);
  EXPECT_EQ(RunCommand(Skybake() + " convert --help", dir), 0);
  EXPECT_EQ(RunCommand(Skybake() + " info --help", dir), 0);
  EXPECT_EQ(RunCommand(Skybake() + " info", dir), 1);
  // Converting over a file the manifest lists would break the set.
  EXPECT_EQ(RunCommand(Skybake() + " convert --half " + in + " " + ShellQuote(Lut() / "irradiance.ktx2"), dir, nullptr,
                       &err), 1);
  EXPECT_NE(err.find("is listed in"), std::string::npos) << err;
  EXPECT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(dir.path() / "none.exr") + " " +
                           ShellQuote(dir.path() / "x.exr"), dir, nullptr, &err), 3);
  testing::WriteText(dir.path() / "foreign.ktx2", "plain text");
  EXPECT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(dir.path() / "foreign.ktx2") + " " +
                           ShellQuote(dir.path() / "x.exr"), dir, nullptr, &err), 3);
  EXPECT_EQ(Lines(err).size(), 1u) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "x.exr"));
  // A listed file that changed since the bake is refused, not converted.
  TempDir copy;
  const fs::path lut = Copy(copy);
  FlipByte(lut / "irradiance.exr", fs::file_size(lut / "irradiance.exr") - 3);
  EXPECT_EQ(RunCommand(Skybake() + " convert " + ShellQuote(lut / "irradiance.exr") + " " +
                           ShellQuote(dir.path() / "x.ktx2"), dir, nullptr, &err), 3);
  EXPECT_NE(err.find("checksum mismatch"), std::string::npos) << err;
}

TEST(BakeFormats, FormatOptionAndHalfReport) {
  TempDir dir;
  std::string out, err;
  const fs::path lut = dir.path() / "k";
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(lut) + kSmallBake + " --format ktx2 --half --json",
                       dir, &out, &err), 0)
      << err;
  for (const std::string& table : kTables) {
    EXPECT_TRUE(fs::exists(lut / (table + ".ktx2"))) << table;
    EXPECT_FALSE(fs::exists(lut / (table + ".exr"))) << table;
  }
  const json report = json::parse(out);
  EXPECT_EQ(report["formats"], json::array({"ktx2"}));
  EXPECT_EQ(report["files"].size(), 16u);  // four tables, eleven runtime files (four languages) and the manifest
  for (const std::string& table : kTables) {
    EXPECT_LE(report["half_error"][table]["max_relative_error"].get<double>(), std::ldexp(1.0, -11)) << table;
  }
  EXPECT_NE(err.find("half: scattering"), std::string::npos) << err;
  const Manifest manifest = ReadManifest(lut);
  ASSERT_EQ(manifest.table_files.size(), 4u);
  for (const ManifestFile& f : manifest.table_files) EXPECT_EQ(f.pixel_type, PixelType::kHalf);

  EXPECT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(lut) + kSmallBake + " --format png", dir, nullptr,
                       &err), 1);
  EXPECT_NE(err.find("unknown format 'png'"), std::string::npos) << err;
  EXPECT_EQ(Lines(err).size(), 1u) << err;
}

// Same input twice, and --threads 1 against --threads 2: identical table
// files in both formats and both pixel types.
TEST(BakeFormats, RebakesAreByteIdenticalInBothFormats) {
  TempDir dir;
  for (const char* half : {"", " --half"}) {
    const fs::path a = dir.path() / "a", b = dir.path() / "b", c = dir.path() / "c";
    ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(a) + kSmallBake + half + " --threads 2", dir), 0);
    ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(b) + kSmallBake + half + " --threads 2", dir), 0);
    ASSERT_EQ(RunCommand(Skybake() + " bake earth -q -o " + ShellQuote(c) + kSmallBake + half + " --threads 1", dir), 0);
    for (const std::string& table : kTables) {
      for (const char* extension : {".exr", ".ktx2"}) {
        const std::string file = table + extension;
        const std::string bytes = ReadText(a / file);
        EXPECT_FALSE(bytes.empty()) << file;
        EXPECT_TRUE(bytes == ReadText(b / file)) << file << half << ": same input twice";
        EXPECT_TRUE(bytes == ReadText(c / file)) << file << half << ": threads 2 vs 1";
      }
    }
    json ma = json::parse(ReadText(a / kManifestFileName)), mc = json::parse(ReadText(c / kManifestFileName));
    EXPECT_NE(ma["command"], mc["command"]);  // the command line is recorded...
    ma.erase("command");
    mc.erase("command");
    EXPECT_EQ(ma, mc);  // ...and is the only difference
    fs::remove_all(a), fs::remove_all(b), fs::remove_all(c);
  }
}

}  // namespace
}  // namespace skybake
