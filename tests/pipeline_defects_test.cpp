// Regression tests for defects of issue 50 ("what a pipeline trusts"), each
// named after its defect (PipelineDefects.D<N>_..., N the number).
// The command-line tests run testing::Skybake() (SKYBAKE_TEST_EXE picks
// another build, e.g. one from before the fix, to see them fail there) on
// small bakes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "formats/query_csv.h"
#include "render/image_files.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::Lines;
using testing::ReadText;
using testing::RunCommand;
using testing::ShellQuote;
using testing::Skybake;
using testing::TempDir;
using testing::WriteText;

const std::string& kSmallTables = testing::kSmallTableOptions;
const std::string kSmallBake = " -q" + testing::kSmallBakeOptions;

const fs::path kSource = SKYBAKE_SOURCE_DIR;

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Bakes `atmosphere` with the small settings and `extra` arguments into `lut`.
void SmallBake(const TempDir& dir, const std::string& atmosphere, const fs::path& lut, const std::string& extra = "") {
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " bake " + atmosphere + " -o " + ShellQuote(lut) + kSmallBake + extra, dir, nullptr,
                       &err),
            0)
      << err;
}

// Runs a command that must fail with `code` and one line on stderr; that line.
std::string OneLineFailure(const std::string& command, const TempDir& dir, int code) {
  std::string out, err;
  EXPECT_EQ(RunCommand(command, dir, &out, &err), code) << command << "\n" << err;
  EXPECT_EQ(Lines(err).size(), 1u) << command << "\n" << err;
  return err;
}

// ---- 5: plots of a spectral set ----

// A spectral set holds CIE X, Y, Z in photometric units (Y in cd m^-2, lux
// for irradiance): `info --plot` names its channels X, Y, Z and its units
// so, where it named the atmosphere's wavelengths in W m^-2 sr^-1 nm^-1. A
// three-wavelength set keeps its wavelengths and radiometric units.
TEST(PipelineDefects, D05_InfoPlotLabelsASpectralSetInXyzAndCandelas) {
  TempDir dir;
  SmallBake(dir, "earth", dir.path() / "xyz", " --wavelengths 3");
  SmallBake(dir, "earth", dir.path() / "rgb");
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " info " + ShellQuote(dir.path() / "xyz") + " --plot " + ShellQuote(dir.path() / "xyz_plots"),
                       dir, nullptr, &err),
            0)
      << err;
  ASSERT_EQ(RunCommand(Skybake() + " info " + ShellQuote(dir.path() / "rgb") + " --plot " + ShellQuote(dir.path() / "rgb_plots"),
                       dir, nullptr, &err),
            0)
      << err;
  for (const char* plot : {"lut_transmittance", "lut_sky_radiance", "lut_irradiance", "lut_sunset"}) {
    SCOPED_TRACE(plot);
    const std::string xyz = ReadText(dir.path() / "xyz_plots" / (std::string(plot) + ".svg"));
    const std::string rgb = ReadText(dir.path() / "rgb_plots" / (std::string(plot) + ".svg"));
    ASSERT_FALSE(xyz.empty());
    ASSERT_FALSE(rgb.empty());
    // No wavelength and no spectral unit on a spectral set's plots.
    EXPECT_FALSE(Contains(xyz, "680 nm") || Contains(xyz, "550 nm") || Contains(xyz, "440 nm")) << plot;
    EXPECT_FALSE(Contains(xyz, "nm^-1")) << plot;
    EXPECT_TRUE(Contains(rgb, "nm")) << plot;
  }
  const std::string sky = ReadText(dir.path() / "xyz_plots" / "lut_sky_radiance.svg");
  EXPECT_TRUE(Contains(sky, "(Y)")) << "the sky radiance plot shows channel Y";
  EXPECT_TRUE(Contains(sky, "cd m^-2"));
  EXPECT_TRUE(Contains(ReadText(dir.path() / "xyz_plots" / "lut_sunset.svg"), "luminance Y (cd m^-2)"));
  EXPECT_TRUE(Contains(ReadText(dir.path() / "xyz_plots" / "lut_irradiance.svg"), "lux"));
  EXPECT_TRUE(Contains(ReadText(dir.path() / "xyz_plots" / "lut_transmittance.svg"), "X, 0 km"));
  EXPECT_TRUE(Contains(ReadText(dir.path() / "rgb_plots" / "lut_sky_radiance.svg"), "W m^-2 sr^-1 nm^-1"));
  EXPECT_TRUE(Contains(ReadText(dir.path() / "rgb_plots" / "lut_sky_radiance.svg"), "(550 nm)"));
}

// ---- 7: auto exposure from space at twilight ----

// The luminance Y = 0.2126 R + 0.7152 G + 0.0722 B of each pixel with Y > 0
// of a linear EXR written by render.
std::vector<double> PositiveLuminance(const fs::path& path) {
  std::vector<double> y;
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) return y;
  const OIIO::ImageSpec& spec = input->spec();
  std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
  input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
  for (std::size_t i = 0; i < std::size_t(spec.width) * spec.height; ++i) {
    const float* p = &pixels[i * spec.nchannels];
    const double v = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    if (v > 0.0) y.push_back(v);
  }
  std::sort(y.begin(), y.end());
  return y;
}

// The space-to-ground scene's planet from space with the sun 95 degrees
// from the zenith below the camera is half in the night: the median of
// every pixel exposed for the night side (EV 10.3) and drew the lit limb
// pure white. Exposed for the lit part, the limb keeps its colour, and a
// daylight view, lit all over, is still exposed on the median of all of it.
TEST(PipelineDefects, D07_AutoExposureDoesNotBlowOutTheLitLimbFromSpaceAtTwilight) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", images = dir.path() / "images";
  SmallBake(dir, "earth", lut, " --scene " + ShellQuote(kSource / "examples/scenes/space-to-ground.toml"));
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(images) +
                           " --views space --size 64 --sun-zenith 95,30 --json",
                       dir, &out, &err),
            0)
      << err;
  const nlohmann::json report = nlohmann::json::parse(out);
  ASSERT_EQ(report["images"].size(), 2u);
  const double twilight_ev = report["images"][0]["exposure_ev"].get<double>();
  const double daylight_ev = report["images"][1]["exposure_ev"].get<double>();

  // The lit limb: no pixel clipped to white, and the brightest about as
  // exposed as the daylight planet's brightest.
  const render::Rgb8 png = render::ReadPng(images / "space_sz95.png");
  int white = 0, brightest = 0;
  for (std::size_t i = 0; i < png.rgb.size(); i += 3) {
    const int low = std::min({png.rgb[i], png.rgb[i + 1], png.rgb[i + 2]});
    white += low == 255 ? 1 : 0;
    brightest = std::max(brightest, low);
  }
  EXPECT_EQ(white, 0) << "EV " << twilight_ev;
  EXPECT_LT(brightest, 240) << "EV " << twilight_ev;
  EXPECT_LT(twilight_ev, daylight_ev + 2.0);

  // Daylight from space: lit all over, so the median of every pixel, as
  // before, within the few night pixels at the planet's rim.
  const std::vector<double> y = PositiveLuminance(images / "space_sz30.exr");
  ASSERT_FALSE(y.empty());
  EXPECT_NEAR(daylight_ev, std::log2(-std::log(1.0 - render::kAutoExposureMidGrey) / y[y.size() / 2]), 0.05);
}

// ---- 8: options that contradict each other ----

TEST(PipelineDefects, D08_ConflictingOptionsAreUsageErrors) {
  TempDir dir;
  // Zstandard supercompresses KTX2 files: with EXR files only there is nothing to compress.
  std::string err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "exr") + kSmallBake +
                                       " --format exr --ktx2-supercompression zstd",
                                   dir, 1);
  EXPECT_TRUE(Contains(err, "--ktx2-supercompression")) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "exr"));
  // The same through a scene that writes EXR only.
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "sunset") + kSmallBake + " --scene " +
                           ShellQuote(kSource / "examples/scenes/sunset-cinematic.toml") + " --ktx2-supercompression zstd",
                       dir, 1);
  EXPECT_TRUE(Contains(err, "output.formats")) << err;
  // And converting to an EXR file.
  SmallBake(dir, "earth", dir.path() / "set", " --format ktx2");
  err = OneLineFailure(Skybake() + " convert " + ShellQuote(dir.path() / "set" / "transmittance.ktx2") + " " +
                           ShellQuote(dir.path() / "t.exr") + " --ktx2-supercompression zstd",
                       dir, 1);
  EXPECT_FALSE(fs::exists(dir.path() / "t.exr"));

  // A scene names each table's precision (this one its transmittance
  // explicitly as float); --half would override it.
  const fs::path scene = dir.path() / "float-transmittance.toml";
  std::string text = ReadText(kSource / "examples/scenes/ground-daytime-game.toml");
  text.replace(text.find("[precision]"), std::string("[precision]").size(),
               "[precision]\ntransmittance = \"float\"");
  WriteText(scene, text);
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "game") + kSmallBake + " --scene " +
                           ShellQuote(scene) + " --half",
                       dir, 1);
  EXPECT_TRUE(Contains(err, "--half")) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "game"));
}

// ---- 9: bad option values exit 1 ----

TEST(PipelineDefects, D09_BadOptionValuesExitOne) {
  TempDir dir;
  const fs::path out = dir.path() / "out";
  for (const char* count : {"2", "-1", "1"}) {
    const std::string err =
        OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(out) + kSmallBake + " --wavelengths " + count, dir, 1);
    EXPECT_TRUE(Contains(err, "--wavelengths")) << err;
  }
  WriteText(dir.path() / "q.csv", "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,30,0\n");
  OneLineFailure(Skybake() + " reference earth --in " + ShellQuote(dir.path() / "q.csv") + " --wavelengths 2 --paths 64",
                 dir, 1);
  SmallBake(dir, "earth", dir.path() / "lut");
  for (const char* zenith : {"200", "-5", "30,181"}) {
    OneLineFailure(Skybake() + " render -q " + ShellQuote(dir.path() / "lut") + " -o " + ShellQuote(dir.path() / "images") +
                       " --views fisheye --size 8 --sun-zenith " + zenith,
                   dir, 1);
  }
  // An angle render takes but these tables do not reach stays the input's fault.
  OneLineFailure(Skybake() + " render -q " + ShellQuote(dir.path() / "lut") + " -o " + ShellQuote(dir.path() / "images") +
                     " --views fisheye --size 8 --sun-zenith 150",
                 dir, 2);
  const std::string err = OneLineFailure(
      Skybake() + " fit earth --json --altitude-min-m 5000 --altitude-max-m 100", dir, 1);
  EXPECT_TRUE(Contains(err, "--altitude-min-m")) << err;
  OneLineFailure(Skybake() + " fit earth --json --altitude-min-m -1", dir, 1);
}

// ---- 10: eval's queries ----

TEST(PipelineDefects, D10_EvalParsesQueriesStrictly) {
  TempDir dir;
  const fs::path lut = dir.path() / "lut", queries = dir.path() / "q.csv";
  SmallBake(dir, "earth", lut);
  const std::string eval = Skybake() + " eval " + ShellQuote(lut) + " --in " + ShellQuote(queries);
  const std::string header = "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n";

  // Decimal numbers only: one line naming the file, the line and the column.
  for (const char* bad : {"0x10", "inf", "nan", "1e", "12abc", "1,5"}) {
    SCOPED_TRACE(bad);
    const std::string text = header + "0,0,30,0\n0," + std::string("\"") + bad + "\",30,0\n";
    WriteText(queries, text);
    const std::string err = OneLineFailure(eval, dir, 2);
    EXPECT_TRUE(Contains(err, queries.string() + ":3: view_zenith_deg")) << err;
    // The location, as --json errors report it.
    try {
      ParseQueryCsv(text, "q.csv");
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.location().file, "q.csv");
      EXPECT_EQ(e.location().line, 3);
      EXPECT_EQ(e.location().key, "view_zenith_deg");
    }
  }
  WriteText(queries, header + "0,0x10,30,0\n");
  EXPECT_TRUE(Contains(OneLineFailure(eval, dir, 2), ":2: view_zenith_deg = '0x10' is not a number")) << "unquoted";

  // A sun past the tables' lowest sun: refused as render refuses it, same
  // message, same exit code.
  WriteText(queries, header + "0,0,30,0\n0,0,150,0\n");
  const std::string eval_error = OneLineFailure(eval, dir, 2);
  EXPECT_TRUE(Contains(eval_error, ":3: sun_zenith_deg = 150 ")) << eval_error;
  const std::string render_error =
      OneLineFailure(Skybake() + " render -q " + ShellQuote(lut) + " -o " + ShellQuote(dir.path() / "images") +
                         " --views fisheye --size 8 --sun-zenith 150",
                     dir, 2);
  const std::string problem = "is outside the tables' range 0..102.00 degrees";
  EXPECT_TRUE(Contains(eval_error, "150 " + problem)) << eval_error;
  EXPECT_TRUE(Contains(render_error, "150 " + problem)) << render_error;
  // The lowest sun itself is answered.
  WriteText(queries, header + "0,0,102,0\n");
  std::string out, err;
  EXPECT_EQ(RunCommand(eval, dir, &out, &err), 0) << err;

  // RFC 4180 fields: quoted names and numbers, a quoted comma, a doubled
  // quote and a line break inside a group label, CRLF line ends; the label
  // is echoed quoted again, and the answers are those of the plain query.
  WriteText(queries, "\"altitude_m\",view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg,group\r\n"
                     "\"100\", 45 ,\"30\",0,\"a, \"\"b\"\"\nc\"\r\n"
                     "100,45,30,0,plain\r\n");
  ASSERT_EQ(RunCommand(eval, dir, &out, &err), 0) << err;
  const std::vector<std::string> lines = Lines(out);
  ASSERT_EQ(lines.size(), 4u) << out;  // the header, the quoted row over two lines, the plain row
  EXPECT_EQ(lines[1], "100,45,30,0,\"a, \"\"b\"\"");
  EXPECT_EQ(lines[2].substr(0, 2), "c\"");
  EXPECT_EQ(lines[2].substr(2), lines[3].substr(std::string("100,45,30,0,plain").size()));
  // A quote left open is one line naming where the field began.
  WriteText(queries, header + "0,0,30,0\n0,0,\"30,0\n");
  EXPECT_TRUE(Contains(OneLineFailure(eval, dir, 2), ":3: field 3: a quoted field is not closed"));
}

// ---- 13: the smaller defects ----

// A scene that keeps the atmosphere's lowest sun (space views) said "lowest
// sun 102.00 deg instead of 102.00 deg"; a scene that lowers it still says
// what it is instead of.
TEST(PipelineDefects, D13_SceneSummarySaysInsteadOnlyWhereTheLowestSunMoved) {
  TempDir dir;
  const std::regex same("lowest sun ([0-9.]+) deg instead of \\1 deg");
  std::string err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "space") + kSmallTables + " --scene " +
                           ShellQuote(kSource / "examples/scenes/space-to-ground.toml"),
                       dir, nullptr, &err),
            0)
      << err;
  EXPECT_FALSE(std::regex_search(err, same)) << err;
  EXPECT_TRUE(Contains(err, "the lowest sun 102.00 deg, as in the full bake")) << err;
  ASSERT_EQ(RunCommand(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "game") + kSmallTables + " --scene " +
                           ShellQuote(kSource / "examples/scenes/ground-daytime-game.toml"),
                       dir, nullptr, &err),
            0)
      << err;
  EXPECT_TRUE(std::regex_search(err, std::regex("lowest sun 99\\.[0-9]+ deg instead of 102.00 deg"))) << err;
}

// A scene's unknown format or precision reads as the atmosphere files' own
// errors do, "KEY: unknown format "png" (expected ...)", not "KEY: = "png"".
TEST(PipelineDefects, D13_SceneValueErrorsReadWell) {
  TempDir dir;
  std::string text = ReadText(kSource / "examples/scenes/ground-daytime-game.toml");
  const fs::path scene = dir.path() / "bad.toml";
  WriteText(scene, text.substr(0, text.find("[output]")) + "[output]\nformats = [\"png\"]\n");
  std::string err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + kSmallBake +
                                       " --scene " + ShellQuote(scene),
                                   dir, 2);
  EXPECT_TRUE(Contains(err, "output.formats[0]: unknown format \"png\" (expected \"exr\" or \"ktx2\")")) << err;
  EXPECT_FALSE(Contains(err, ": =")) << err;
  text.replace(text.find("scattering = \"half\""), std::string("scattering = \"half\"").size(),
               "scattering = \"double\"");
  WriteText(scene, text);
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + kSmallBake + " --scene " +
                           ShellQuote(scene),
                       dir, 2);
  EXPECT_TRUE(Contains(err, "precision.scattering: unknown precision \"double\"")) << err;
}

// BakeSettings, the --orders help and its own out-of-range message call 0
// auto: `--orders 0` bakes as `--orders auto` does.
TEST(PipelineDefects, D13_OrdersZeroIsAuto) {
  TempDir dir;
  std::string out, err;
  const std::string bake = Skybake() + " bake earth -q --json" + kSmallTables + " -o ";
  ASSERT_EQ(RunCommand(bake + ShellQuote(dir.path() / "zero") + " --orders 0", dir, &out, &err), 0) << err;
  const nlohmann::json zero = nlohmann::json::parse(out);
  EXPECT_EQ(zero["orders"], "auto");
  ASSERT_EQ(RunCommand(bake + ShellQuote(dir.path() / "auto") + " --orders auto", dir, &out, &err), 0) << err;
  EXPECT_EQ(nlohmann::json::parse(out)["orders_used"], zero["orders_used"]);
  EXPECT_EQ(nlohmann::json::parse(ReadText(dir.path() / "zero" / "skybake.json"))["bake"]["orders"], "auto");
  OneLineFailure(bake + ShellQuote(dir.path() / "minus") + " --orders -1", dir, 1);
}

// --threads has a bound, stated in --help; beyond it a usage error.
TEST(PipelineDefects, D13_ThreadsAreBounded) {
  TempDir dir;
  std::string out;
  ASSERT_EQ(RunCommand(Skybake() + " bake --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "at most 1024")) << out;
  for (const char* threads : {"100000", "1025", "-1"}) {
    const std::string err =
        OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + kSmallBake + " --threads " + threads,
                       dir, 1);
    EXPECT_TRUE(Contains(err, "threads")) << err;
  }
  WriteText(dir.path() / "q.csv", "altitude_m,view_zenith_deg,sun_zenith_deg,view_sun_azimuth_deg\n0,0,30,0\n");
  OneLineFailure(Skybake() + " reference earth --in " + ShellQuote(dir.path() / "q.csv") + " --paths 64 --threads 100000",
                 dir, 1);
}

// {name} in -o: said in --help what it is for standard input (stdin), and
// any other {...} refused as a usage error instead of becoming a folder.
TEST(PipelineDefects, D13_OutputPatternsNameOnlyKnownPlaceholders) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " bake --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "stdin for standard input")) << out;
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "{atmosphere}") + kSmallBake, dir, 1);
  EXPECT_TRUE(Contains(err, "{atmosphere}")) << err;
  EXPECT_FALSE(fs::exists(dir.path() / "{atmosphere}"));
  OneLineFailure(Skybake() + " bake earth mars -o " + ShellQuote(dir.path() / "{name}-{Name}") + kSmallBake, dir, 1);
  // Standard input's {name} is stdin, as --help and docs/cli.md say.
  ASSERT_EQ(RunCommand(Skybake() + " bake - -o " + ShellQuote(dir.path() / "sets/{name}") + kSmallBake + " < " +
                           ShellQuote(kSource / "examples/atmospheres/earth.toml"),
                       dir, nullptr, &err),
            0)
      << err;
  EXPECT_TRUE(fs::exists(dir.path() / "sets" / "stdin" / "skybake.json"));
  EXPECT_TRUE(Contains(ReadText(kSource / "docs/cli.md"), "`stdin` for standard input"));
}

// An error about a file names it by the path the user gave, in the message
// and in the --json error's `file`: atmosphere files, scene files and query
// files alike (they named only the base name).
TEST(PipelineDefects, D13_ErrorsNameTheFileByThePathGiven) {
  TempDir dir;
  fs::create_directories(dir.path() / "sub");
  WriteText(dir.path() / "sub" / "bad.toml", "name = \"x\"\n[planet]\nground_radius_km = -1\n");
  std::string out, err;
  // A relative path stays relative.
  EXPECT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate sub/bad.toml --json", dir, &out,
                       &err),
            2);
  EXPECT_EQ(err.rfind("skybake: sub/bad.toml: ", 0), 0u) << err;
  EXPECT_EQ(nlohmann::json::parse(out)["error"]["file"], "sub/bad.toml");
  // An absolute one stays absolute.
  EXPECT_EQ(RunCommand(Skybake() + " validate " + ShellQuote(dir.path() / "sub" / "bad.toml") + " --json", dir, &out, &err),
            2);
  EXPECT_EQ(nlohmann::json::parse(out)["error"]["file"], (dir.path() / "sub" / "bad.toml").string());
  // A scene file, and a scene that does not fit the planet.
  WriteText(dir.path() / "sub" / "scene.toml", "name = \"x\"\n");
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + kSmallBake + " --scene " +
                           ShellQuote(dir.path() / "sub" / "scene.toml"),
                       dir, 2);
  EXPECT_EQ(err.rfind("skybake: " + (dir.path() / "sub" / "scene.toml").string() + ": ", 0), 0u) << err;
  WriteText(dir.path() / "sub" / "high.toml",
            "name = \"x\"\n[effects]\nsky = true\n[camera]\naltitude_km = [0, 500]\n[sun]\nzenith_deg = [0, 90]\n");
  err = OneLineFailure(Skybake() + " bake earth -o " + ShellQuote(dir.path() / "x") + kSmallBake + " --scene " +
                           ShellQuote(dir.path() / "sub" / "high.toml"),
                       dir, 2);
  EXPECT_EQ(err.rfind("skybake: " + (dir.path() / "sub" / "high.toml").string() + ": camera.altitude", 0), 0u) << err;
}

// The docs say what the program does: render's default suns (30 and 85
// degrees, as `render --help` states), and that a bare word names the
// preset even where a file of that name exists (as `bake --help` says).
TEST(PipelineDefects, D13_DocsSayWhatTheProgramDoes) {
  TempDir dir;
  std::string out, err;
  ASSERT_EQ(RunCommand(Skybake() + " render --help", dir, &out), 0);
  EXPECT_TRUE(Contains(out, "=[30,85]")) << out;
  const std::string cli = ReadText(kSource / "docs/cli.md");
  EXPECT_TRUE(Contains(cli, "`--sun-zenith 30,85`"));
  EXPECT_FALSE(Contains(cli, "--sun-zenith 0,60,85"));

  // A file named earth beside the command: `validate earth` still reads the preset.
  WriteText(dir.path() / "earth", "name = \"not-the-preset\"\n");
  ASSERT_EQ(RunCommand("cd " + ShellQuote(dir.path()) + " && " + Skybake() + " validate earth --json", dir, &out, &err), 0)
      << err;
  EXPECT_EQ(nlohmann::json::parse(out)["name"], "earth");
  const std::string atmospheres = ReadText(kSource / "examples/atmospheres/README.md");
  EXPECT_FALSE(Contains(atmospheres, "reads FILE when\n  it exists, otherwise the preset"));
  EXPECT_TRUE(Contains(atmospheres, "reads the preset\n  of that name when there is one, even where a file of that "
                                    "name exists"));
}

// The README's first command, scripts/skybake, builds the skybake executable
// only (7 min 46 s for every target on a fresh machine, the tests included);
// scripts/test still builds everything it runs.
TEST(PipelineDefects, D13_TheFirstCommandBuildsOnlySkybake) {
  const std::string skybake = ReadText(kSource / "scripts/skybake");
  EXPECT_TRUE(Contains(skybake, "scripts/build.sh\" skybake")) << skybake;
  const std::string build = ReadText(kSource / "scripts/build.sh");
  EXPECT_TRUE(Contains(build, "--target \"$@\"")) << build;
  const std::string test = ReadText(kSource / "scripts/test");
  EXPECT_TRUE(Contains(test, "scripts/build.sh\"\n")) << test;
}

}  // namespace
}  // namespace skybake
