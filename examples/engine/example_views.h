// What the two engine examples share: their command line, the baked set and
// the shipped snippet they load, the `fisheye` and `aerial` views of
// `skybake render` (render/views.h) as the values pixel_radiance.glsl reads,
// and the EXR and PNG files they write. engine_example.cpp draws the views
// with OpenGL ES, vulkan_example.cpp with a Vulkan compute shader.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "render/image_files.h"

namespace skybake::engine_example {

struct Arguments {
  std::string program;  // the example's name, for its messages
  std::string lut_dir;
  std::string output_dir;
  double sun_zenith_deg = 30.0;
  double sun_azimuth_deg = 0.0;
  int size = 256;
  double altitude_m = 100.0;
  std::string format;  // empty: what LoadLutSet prefers
};

// The set and the snippet files of `language_extension` ("glsl") exactly as
// the bake shipped them, definitions, constants and functions in that order.
// Prints on stderr what a scene's set leaves out, and so what the views
// cannot show.
struct LoadedSet {
  LutSet luts;
  std::string snippet;
};
LoadedSet LoadSet(const Arguments& args);

// One view: the values pixel_radiance.glsl reads.
struct View {
  const char* name;  // "fisheye", "aerial"
  int view;          // 0: fisheye, 1: aerial
  int width, height;
  float camera_altitude;
  glsl::vec3 sun_direction, forward, right, camera_up, ground_albedo;
  float cos_disc, disc_scale;
};
std::vector<View> MakeViews(const Arguments& args, const LutSet& luts);

// The shared shading (pixel_radiance.glsl).
std::string PixelRadianceGlsl();

// Writes each view's linear EXR and tone-mapped PNG once every view has
// rendered; InternalError for a pixel that is not finite.
void WriteViews(const Arguments& args, const LutSet& luts, const std::vector<View>& views,
                const std::vector<render::Image>& images);

// Parses the command line into Arguments, runs `run` and maps errors to
// skybake's exit codes: 1 usage, 2 invalid input, 3 I/O, 4 internal.
int RunExample(int argc, char** argv, const std::string& name, const std::string& description,
               const std::function<void(const Arguments&)>& run);

}  // namespace skybake::engine_example
