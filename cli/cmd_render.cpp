// `skybake render`: preview images of a baked table set through the CPU twin
// (render/views.h), as linear EXR and tone-mapped sRGB PNG, a contact sheet
// of the times of day, and optionally plots of table slices.
#include <chrono>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "bake/colour.h"
#include "bake/scene.h"
#include "cli/command_line.h"
#include "cli/commands.h"
#include "cli/progress.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "core/version.h"
#include "formats/lut_files.h"
#include "render/image_files.h"
#include "render/lut_plots.h"
#include "render/views.h"
#include "report/twin_query.h"
#include "shaders_runtime/twin.h"

namespace skybake::cli {

namespace {

struct RenderArguments {
  std::string lut_dir;
  std::string output_dir;
  std::vector<double> sun_zenith_deg = {30.0, 85.0};
  double sun_azimuth_deg = 0.0;
  int size = 512;
  std::vector<std::string> views = {"fisheye", "panorama", "space", "aerial"};
  std::string exposure = "auto";  // "auto" or EV (render::AutoExposureEv)
  double altitude_m = 100.0;
  double ground_albedo = -1.0;  // < 0: the atmosphere's
  bool plots = false;
  bool quiet = false;
  bool json = false;
};

std::string ZenithTag(double zenith_deg) {
  char tag[32];
  std::snprintf(tag, sizeof(tag), "sz%g", zenith_deg);
  return tag;
}


// A scene's bake holds only what its scene shows (bake/scene.h): refuses the
// views it cannot render, and the suns and camera altitudes eval would
// refuse for its sky.
void CheckSceneCanRender(const Scene& scene, double bottom_radius_m, const RenderArguments& args,
                         const std::vector<render::View>& views) {
  const SceneEffects& e = scene.effects;
  const std::string of_scene = "the scene '" + scene.name + "' of " + args.lut_dir;
  auto refuse = [&](const std::string& what) { throw InputError("render: " + what + " is not in " + of_scene); };
  for (double z : args.sun_zenith_deg) {
    Query sky;
    sky.altitude_m = args.altitude_m, sky.sun_zenith_deg = z;
    std::vector<std::string> unused;
    const std::string problem = SceneQueryProblem(scene, bottom_radius_m, false, &sky, &unused);
    if (!problem.empty()) throw InputError("render: " + problem + " (" + of_scene + ")");
  }
  for (render::View view : views) {
    const std::string name = std::string("view '") + render::ToString(view) + "'";
    if (view == render::View::kSpace && !e.space_views) refuse(name + " (effects.space_views)");
    // Every view but the fisheye shows the ground, lit by the sun and the
    // sky and seen through the air.
    if (view != render::View::kFisheye && !(e.ground_irradiance && e.aerial_perspective)) {
      refuse(name + " (the ground, which needs ground_irradiance and aerial_perspective)");
    }
  }
}

// The fixed exposure `--exposure` gives; nullopt for "auto".
std::optional<double> ParseExposure(const std::string& text) {
  if (text == "auto") return std::nullopt;
  std::size_t used = 0;
  double ev = 0.0;
  try {
    ev = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(ev))
    throw UsageError("render: --exposure must be 'auto' or a number of EV, not '" + text + "'");
  return ev;
}

void RunRender(const RenderArguments& args) {
  const std::optional<double> fixed_exposure = ParseExposure(args.exposure);
  std::vector<render::View> views;
  for (const std::string& name : args.views) {
    render::View view;
    if (!render::ParseView(name, &view))
      throw UsageError("render: unknown view '" + name + "' (fisheye, panorama, space, aerial)");
    views.push_back(view);
  }
  if (views.empty() && !args.plots) throw UsageError("render: nothing to do; give --views or --plots");

  for (double z : args.sun_zenith_deg) {
    if (!(z >= 0.0 && z <= 180.0)) {
      char message[96];
      std::snprintf(message, sizeof(message), "render: --sun-zenith %g is not an angle from the zenith (0 to 180)", z);
      throw UsageError(message);
    }
  }

  LutSet luts = LoadLutSet(args.lut_dir);
  // An angle the option takes that these tables do not reach: the set is
  // what cannot answer it.
  for (double z : args.sun_zenith_deg) {
    const std::string problem = report::SunZenithOutsideTables(luts.parameters, z);
    if (!problem.empty()) {
      char value[32];
      std::snprintf(value, sizeof(value), "%g", z);
      throw InputError("render: --sun-zenith " + std::string(value) + " " + problem);
    }
  }
  if (!(args.altitude_m >= 0.0 && args.altitude_m < luts.atmosphere.top_radius_m - luts.atmosphere.bottom_radius_m))
    throw InputError("render: --altitude-m must lie inside the atmosphere");
  if (luts.scene) CheckSceneCanRender(*luts.scene, luts.atmosphere.bottom_radius_m, args, views);
  EnsureWritableDirectory(args.output_dir);
  const std::filesystem::path out_dir(args.output_dir);

  TwinTables tables = MakeTwinTables(luts);
  Twin twin(tables);
  // A spectral set's twin answers CIE XYZ (docs/colour.md): its images are
  // converted to linear sRGB, whose white is D65, and not white-balanced to
  // the sun; a three-wavelength set's are balanced so that sunlight is neutral.
  const bool colour = luts.colour.has_value();
  const glsl::vec3 white = colour ? glsl::vec3(1.0) : render::WhiteBalance(luts.parameters.solar_irradiance);
  const glsl::vec3 albedo = args.ground_albedo >= 0.0 ? glsl::vec3(args.ground_albedo) : luts.atmosphere.ground_albedo;

  std::size_t total_rows = 0;
  for (render::View view : views) total_rows += render::ViewHeight(view, args.size) * args.sun_zenith_deg.size();
  ProgressBar bar("render", total_rows, args.quiet);
  auto start = std::chrono::steady_clock::now();

  const render::Attributes common = {{"Software", "skybake " SKYBAKE_VERSION},
                                     {"skybake.command_line", CommandLine()}};
  // Every image, plot and the contact sheet go in one set (core/file_io.h):
  // an interrupt or a failure leaves the folder's earlier files as they were.
  StagedFiles staged;
  nlohmann::json images = nlohmann::json::array();
  std::vector<std::vector<render::Rgb8>> columns(args.sun_zenith_deg.size());
  std::vector<std::string> labels, exposure_lines;
  for (std::size_t z = 0; z < args.sun_zenith_deg.size(); ++z) {
    double zenith = args.sun_zenith_deg[z];
    char label[48];
    std::snprintf(label, sizeof(label), "sun zenith %g deg", zenith);
    labels.push_back(label);
    for (render::View view : views) {
      render::ViewSettings settings;
      settings.width = args.size;
      settings.sun_zenith_deg = zenith;
      settings.sun_azimuth_deg = args.sun_azimuth_deg;
      settings.camera_altitude_m = args.altitude_m;
      settings.ground_albedo = albedo;
      render::Image image = render::RenderView(twin, view, settings, [&](int rows) { bar.Advance(rows); });
      if (colour) {
        for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
          const glm::dvec3 rgb = XyzToLinearSrgbMatrix() * glm::dvec3(image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]);
          for (int c = 0; c < 3; ++c) image.rgb[i + c] = float(rgb[c]);
        }
      }

      std::string stem = std::string(render::ToString(view)) + "_" + ZenithTag(zenith);
      render::Attributes exr_attributes = common;
      exr_attributes.push_back({"skybake.view", render::ToString(view)});
      exr_attributes.push_back({"skybake.sun_zenith_deg", std::to_string(zenith)});
      exr_attributes.push_back(
          {"skybake.units", colour ? "cd m^-2 (linear sRGB: Rec. 709 primaries, D65 white, from the set's CIE XYZ)"
                                   : "W m^-2 sr^-1 nm^-1 (linear radiance, R G B = the tables' wavelengths)"});
      render::WriteLinearExr(staged, out_dir / (stem + ".exr"), image, exr_attributes);
      const double exposure_ev = fixed_exposure ? *fixed_exposure : render::AutoExposureEv(image);
      render::Rgb8 png = render::ToneMapToSrgb(image, render::ToneMap{exposure_ev, white});
      render::Attributes png_attributes = common;
      char description[256];
      std::snprintf(description, sizeof(description),
                    "%s view, sun zenith %g deg, exposure %.4g EV (%s), tone curve 1 - exp(-x), sRGB, white "
                    "balance: %s",
                    render::ToString(view), zenith, exposure_ev, fixed_exposure ? "fixed" : "auto",
                    colour ? "none (D65, from CIE XYZ)" : "sunlight neutral");
      char exposure_line[128];
      std::snprintf(exposure_line, sizeof(exposure_line), "render: %s sun zenith %g deg: exposure %.4g EV (%s)",
                    render::ToString(view), zenith, exposure_ev, fixed_exposure ? "fixed" : "auto");
      exposure_lines.push_back(exposure_line);
      png_attributes.push_back({"ImageDescription", description});
      render::WritePng(staged, out_dir / (stem + ".png"), png, png_attributes);
      columns[z].push_back(std::move(png));
      images.push_back({{"view", render::ToString(view)},
                        {"sun_zenith_deg", zenith},
                        {"exposure_ev", exposure_ev},
                        {"width", image.width},
                        {"height", image.height},
                        {"exr", (out_dir / (stem + ".exr")).string()},
                        {"png", (out_dir / (stem + ".png")).string()}});
    }
  }
  bar.Finish();
  if (!args.quiet)
    for (const std::string& line : exposure_lines) std::fprintf(stderr, "%s\n", line.c_str());

  nlohmann::json report = {{"lut_dir", args.lut_dir},
                           {"output_dir", args.output_dir},
                           {"size", args.size},
                           {"exposure", fixed_exposure ? nlohmann::json(*fixed_exposure) : nlohmann::json("auto")},
                           {"sun_azimuth_deg", args.sun_azimuth_deg},
                           {"images", images}};
  if (!views.empty()) {
    std::vector<std::vector<const render::Rgb8*>> sheet_columns;
    for (const auto& column : columns) {
      sheet_columns.emplace_back();
      for (const render::Rgb8& image : column) sheet_columns.back().push_back(&image);
    }
    std::filesystem::path sheet = out_dir / "contact_sheet.png";
    render::WritePng(staged, sheet, render::ContactSheet(sheet_columns, labels), common);
    report["contact_sheet"] = sheet.string();
  }
  if (args.plots) {
    render::PlotFiles plots = render::WriteLutPlots(staged, luts, out_dir, CommandLine());
    nlohmann::json files = nlohmann::json::array();
    for (const auto& f : plots.files) files.push_back(f.string());
    report["plots"] = files;
    report["plots_left_out"] = plots.left_out;
    for (const std::string& line : plots.left_out) std::fprintf(stderr, "render: plot left out: %s\n", line.c_str());
    if (!plots.png_text && !args.quiet) std::fputs("render: no TrueType font found; the PNG plots have no text\n", stderr);
  }
  staged.Commit();
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report["seconds"] = seconds;
  if (!args.quiet)
    std::fprintf(stderr, "render: %zu images in %.1f s into %s\n", images.size(), seconds, args.output_dir.c_str());
  if (args.json) std::printf("%s\n", report.dump(2).c_str());
}

}  // namespace

void AddRenderCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render preview images of baked tables through the CPU twin: a fisheye of the sky, a panorama, the planet "
      "from space and an aerial-perspective strip, as linear EXR and tone-mapped sRGB PNG, plus a contact sheet");
  auto args = std::make_shared<RenderArguments>();
  cmd->add_option("lut_dir", args->lut_dir, "Directory written by `skybake bake`")->required();
  cmd->add_option("-o,--output", args->output_dir, "Output directory (created if needed)")->required()
      ->check(OutputPath());
  cmd->add_option("--sun-zenith", args->sun_zenith_deg,
                  "Sun zenith angles in degrees (0 to 180, and at most the tables' lowest sun), comma separated")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sun-azimuth", args->sun_azimuth_deg, "Sun azimuth in degrees (0: +x; see docs/gallery.md)")
      ->capture_default_str();
  cmd->add_option("--size", args->size, "Image width in pixels (fisheye and space: square; panorama: width/2 "
                                        "high; aerial: width/4 high)")
      ->capture_default_str()
      ->check(CLI::Range(1, 16384));
  cmd->add_option("--views", args->views, "Views to render, comma separated: fisheye, panorama, space, aerial")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--exposure", args->exposure,
                  "Exposure of the PNGs: radiance x 2^EV (after white balance), then 1 - exp(-x), then sRGB. "
                  "A number of EV, or auto: per image, EV = log2(-ln(1 - 0.18) / Y_med), Y_med the median "
                  "luminance (Y = 0.2126 R + 0.7152 G + 0.0722 B of the linear radiance) over the lit pixels that "
                  "show sky (rays that miss the ground; from space, the whole planet; all pixels with Y > 0 if "
                  "none), lit meaning Y at least 1/100 of their 99th percentile (from space at twilight: not the "
                  "night side), so it leaves the tone curve at mid-grey 0.18 before the sRGB transfer. The EV "
                  "used is printed on stderr and recorded in each PNG's ImageDescription and in --json")
      ->capture_default_str();
  cmd->add_option("--altitude-m", args->altitude_m, "Camera altitude of the ground views, metres")
      ->capture_default_str();
  cmd->add_option("--ground-albedo", args->ground_albedo,
                  "Grey Lambertian ground albedo (default: the atmosphere's ground albedo)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--plots", args->plots,
                "Also plot table slices (lut_*.svg and .png); a plot whose table the set leaves out (a scene's "
                "bake) is not drawn and is named on stderr");
  cmd->add_flag("-q,--quiet", args->quiet, "No progress bar or summary on stderr");
  cmd->add_flag("--json", args->json, "Print a JSON report of the files written on stdout");
  cmd->callback([args] { RunRender(*args); });
}

}  // namespace skybake::cli
