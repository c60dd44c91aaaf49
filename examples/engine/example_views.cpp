#include "examples/engine/example_views.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <CLI/CLI.hpp>

#include "core/constants.h"
#include "core/errors.h"
#include "core/file_io.h"
#include "formats/lut_files.h"
#include "shaders_runtime/embedded_text.h"

namespace skybake {
// examples/engine/pixel_radiance.glsl, embedded by CMake.
extern const std::vector<EmbeddedText> kEngineExampleShaderFiles;
}  // namespace skybake

namespace skybake::engine_example {

namespace fs = std::filesystem;

namespace {

constexpr double kDegree = kPi / 180.0;
constexpr double kAerialPitchDeg = 7.0;  // as render/views.cpp

void Validate(const Arguments& args) {
  if (args.size < 4 || args.size > 4096) throw UsageError("--size must be in 4..4096");
  if (!(args.altitude_m >= 0.0 && args.altitude_m <= 1e5)) throw UsageError("--altitude must be in 0..1e5 m");
  if (!(args.sun_zenith_deg >= 0.0 && args.sun_zenith_deg <= 180.0))
    throw UsageError("--sun-zenith must be in 0..180 degrees");
  if (!std::isfinite(args.sun_azimuth_deg)) throw UsageError("--sun-azimuth must be a finite angle");
}

}  // namespace

LoadedSet LoadSet(const Arguments& args) {
  Validate(args);
  LoadOptions load_options;
  if (!args.format.empty()) {
    load_options.format = ParseFileFormat(args.format);
    if (!load_options.format) throw UsageError("--format must be ktx2 or exr, not '" + args.format + "'");
  }
  const fs::path lut_dir(args.lut_dir);
  LoadedSet set;
  set.luts = LoadLutSet(lut_dir, load_options);
  for (const char* file : {"definitions.glsl", "atmosphere_constants.glsl", "functions.glsl"})
    set.snippet += ReadFileText(lut_dir / file);

  // What a scene's bake leaves out, and so what the views draw without
  // (pixel_radiance.glsl); the snippet's macros say the same.
  const LutSet& luts = set.luts;
  const bool aerial_perspective = !luts.scene || luts.scene->effects.aerial_perspective;
  const char* program = args.program.c_str();
  if (luts.scattering.empty()) std::fprintf(stderr, "%s: no scattering table: the sky is black\n", program);
  if (!aerial_perspective)
    std::fprintf(stderr, "%s: no aerial-perspective functions: the ground is drawn unveiled\n", program);
  if (luts.irradiance.empty())
    std::fprintf(stderr, "%s: no irradiance table: the ground is lit by the direct sun only\n", program);
  return set;
}

std::vector<View> MakeViews(const Arguments& args, const LutSet& luts) {
  const double sz = args.sun_zenith_deg * kDegree, az = args.sun_azimuth_deg * kDegree;
  const glsl::vec3 sun(std::sin(sz) * std::cos(az), std::sin(sz) * std::sin(az), std::cos(sz));
  const double pitch = kAerialPitchDeg * kDegree;
  const glsl::vec3 level(std::cos(az), std::sin(az), 0.0), up(0.0, 0.0, 1.0);
  std::vector<View> views;
  struct Spec {
    const char* name;
    int height;
    double pixel_angle;  // as render/views.cpp, for the drawn sun disc
  };
  const Spec specs[] = {{"fisheye", args.size, kPi / args.size},
                        {"aerial", std::max(1, args.size / 4), (kPi / 2) / args.size}};
  for (int v = 0; v < 2; ++v) {
    View view;
    view.name = specs[v].name;
    view.view = v;
    view.width = args.size;
    view.height = specs[v].height;
    view.camera_altitude = float(args.altitude_m);
    view.sun_direction = sun;
    view.forward = level * std::cos(pitch) - up * std::sin(pitch);
    view.right = glsl::vec3(std::sin(az), -std::cos(az), 0.0);
    view.camera_up = level * std::sin(pitch) + up * std::cos(pitch);
    view.ground_albedo = glsl::vec3(luts.atmosphere.ground_albedo);
    const double sun_radius = luts.parameters.sun_angular_radius;
    const double cos_disc = std::cos(std::max(sun_radius, specs[v].pixel_angle));
    view.cos_disc = float(cos_disc);
    view.disc_scale = float((1.0 - std::cos(sun_radius)) / (1.0 - cos_disc));
    views.push_back(view);
  }
  return views;
}

std::string PixelRadianceGlsl() {
  for (const EmbeddedText& file : kEngineExampleShaderFiles)
    if (file.name == "pixel_radiance.glsl") return std::string(file.text);
  throw InternalError("pixel_radiance.glsl is not embedded");
}

void WriteViews(const Arguments& args, const LutSet& luts, const std::vector<View>& views,
                const std::vector<render::Image>& images) {
  for (std::size_t i = 0; i < images.size(); ++i) {
    for (float value : images[i].rgb) {
      if (!std::isfinite(value)) throw InternalError(std::string(views[i].name) + ": a pixel is not finite");
    }
  }
  const render::ToneMap tone{3.3, render::WhiteBalance(luts.parameters.solar_irradiance)};
  const fs::path out_dir(args.output_dir);
  EnsureWritableDirectory(out_dir);
  // The images appear together or not at all.
  StagedFiles staged;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const render::Attributes attributes = {{"skybake:view", views[i].name}};
    render::WriteLinearExr(staged, out_dir / (std::string(views[i].name) + ".exr"), images[i], attributes);
    render::WritePng(staged, out_dir / (std::string(views[i].name) + ".png"), render::ToneMapToSrgb(images[i], tone),
                     attributes);
  }
  staged.Commit();
}

int RunExample(int argc, char** argv, const std::string& name, const std::string& description,
               const std::function<void(const Arguments&)>& run) {
  CLI::App app{description};
  app.name(name);
  Arguments args;
  args.program = name;
  app.add_option("LUT_DIR", args.lut_dir, "A directory written by skybake bake")->required();
  app.add_option("OUT_DIR", args.output_dir, "Where to write fisheye.{exr,png} and aerial.{exr,png}")->required();
  app.add_option("--sun-zenith", args.sun_zenith_deg, "Sun zenith angle, degrees")->capture_default_str();
  app.add_option("--sun-azimuth", args.sun_azimuth_deg, "Sun azimuth (the aerial view looks toward it), degrees")
      ->capture_default_str();
  app.add_option("--size", args.size, "Image width in pixels (the aerial view is a quarter as high)")
      ->capture_default_str();
  app.add_option("--altitude", args.altitude_m, "Camera altitude, metres")->capture_default_str();
  app.add_option("--format", args.format, "Table files to read: ktx2 or exr (default: KTX2 if listed)");
  try {
    app.parse(argc, argv);
    run(args);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s (see --help)\n", name.c_str(), e.what());
    return static_cast<int>(ExitCode::kUsage);
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: %s\n", name.c_str(), e.what());
    return static_cast<int>(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", name.c_str(), e.what());
    return static_cast<int>(ExitCode::kInternal);
  }
  return 0;
}

}  // namespace skybake::engine_example
