// How a Vulkan engine uses a baked set: load the tables with the formats
// library, upload them as sampled images (3D for the scattering tables) with
// one linear, clamp-to-edge sampler (shaders_runtime/README.md), compile the
// three GLSL files the bake wrote into a Vulkan GLSL 4.50 compute shader with
// explicit bindings (glslangValidator -V, as an asset pipeline's shader step
// would), and render. Headless, on whatever Vulkan device there is (Mesa's
// lavapipe runs it on the CPU), it draws the `fisheye` sky and the `aerial`
// view of engine_example.cpp, one invocation per pixel, with the same shading
// (pixel_radiance.glsl), and writes the same EXR and PNG files: the two
// examples and `skybake render` draw the same pictures.
//
//   skybake_vulkan_example LUT_DIR OUT_DIR [--sun-zenith DEG] [--sun-azimuth DEG]
//                          [--size N] [--altitude M] [--format ktx2|exr]
//
// Exit codes as skybake's: 1 usage, 2 invalid input, 3 I/O (including: no
// Vulkan device), 4 internal.
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "examples/engine/example_views.h"
#include "examples/engine/vulkan_compute.h"

using namespace skybake::engine_example;
using skybake::VulkanCompute;

namespace {

// The compute shader around the snippet and pixel_radiance.glsl: after the
// tables (VulkanCompute::kGlslTables), the view's values read from a buffer
// into the globals pixel_radiance.glsl reads, one pixel per invocation, rows
// from the top.
const char* const kComputeDeclarations = R"(
layout(std430, set = 0, binding = 4) readonly buffer ViewValues { vec4 view_values[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Pixels { vec4 radiance_out[]; };
layout(local_size_x = 64) in;
int view;
vec2 image_size;
float camera_altitude;
vec3 sun_direction;
vec3 forward;
vec3 right;
vec3 camera_up;
vec3 ground_albedo;
float cos_disc;
float disc_scale;
)";
const char* const kComputeMain = R"(
void main() {
  view = int(view_values[0].x);
  image_size = view_values[0].yz;
  camera_altitude = view_values[0].w;
  sun_direction = view_values[1].xyz;
  cos_disc = view_values[1].w;
  forward = view_values[2].xyz;
  disc_scale = view_values[2].w;
  right = view_values[3].xyz;
  camera_up = view_values[4].xyz;
  ground_albedo = view_values[5].xyz;
  uint pixel = gl_GlobalInvocationID.x;
  if (pixel >= uint(radiance_out.length())) return;
  uint width = uint(image_size.x);
  vec2 p = vec2(float(pixel % width) + 0.5, float(pixel / width) + 0.5);
  radiance_out[pixel] = vec4(PixelRadiance(p), 1.0);
}
)";

// The view's values in the order kComputeMain reads them.
std::vector<std::array<float, 4>> ViewValues(const View& v) {
  auto f = [](double x) { return float(x); };
  return {{float(v.view), float(v.width), float(v.height), v.camera_altitude},
          {f(v.sun_direction.x), f(v.sun_direction.y), f(v.sun_direction.z), v.cos_disc},
          {f(v.forward.x), f(v.forward.y), f(v.forward.z), v.disc_scale},
          {f(v.right.x), f(v.right.y), f(v.right.z), 0.0f},
          {f(v.camera_up.x), f(v.camera_up.y), f(v.camera_up.z), 0.0f},
          {f(v.ground_albedo.x), f(v.ground_albedo.y), f(v.ground_albedo.z), 0.0f}};
}

// SPIR-V of the compute shader (glslangValidator -V, as an asset pipeline's
// shader step would); InputError with the compiler's first error otherwise.
std::vector<std::uint32_t> CompileCompute(const std::string& source) {
  std::string log;
  std::vector<std::uint32_t> spirv = skybake::CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, source, false, &log);
  if (spirv.empty()) {
    std::istringstream lines(log);
    std::string first_error;
    while (std::getline(lines, first_error) && first_error.find("ERROR") == std::string::npos) {
    }
    throw skybake::InputError("the compute shader does not compile: " + first_error);
  }
  return spirv;
}

void Run(const Arguments& args) {
  const LoadedSet set = LoadSet(args);
  const skybake::LutSet& luts = set.luts;
  const std::vector<View> views = MakeViews(args, luts);
  const std::vector<std::uint32_t> spirv =
      CompileCompute("#version 450\n" + set.snippet + VulkanCompute::kGlslTables + kComputeDeclarations +
                     PixelRadianceGlsl() + kComputeMain);

  std::string why_not;
  std::unique_ptr<VulkanCompute> vk = VulkanCompute::Create(&why_not);
  if (!vk) throw skybake::IoError("no Vulkan device: " + why_not);
  // A table the set leaves out gets a black stand-in: the snippet has no
  // function that samples it, but every binding needs an image.
  const skybake::glsl::Texture& single_mie =
      luts.single_mie_scattering.empty() ? luts.scattering : luts.single_mie_scattering;
  const skybake::glsl::Texture* tables[] = {&luts.transmittance, &luts.scattering, &single_mie, &luts.irradiance};
  for (int binding = 0; binding < VulkanCompute::kTextureCount; ++binding) {
    const skybake::glsl::Texture& t = *tables[binding];
    const bool is_3d = binding == 1 || binding == 2;
    const float black[8] = {};
    if (t.empty()) {
      vk->SetTexture(binding, 1, 1, is_3d ? 2 : 1, black, is_3d ? 8 : 4);
    } else {
      vk->SetTexture(binding, t.width, t.height, t.depth, t.texels.data(), t.texels.size());
    }
  }

  std::vector<skybake::render::Image> rendered;
  for (const View& v : views) {
    const std::size_t pixels = std::size_t(v.width) * v.height;
    const auto radiance = vk->Run(spirv, VulkanCompute::Samplers::kCombined, ViewValues(v), pixels);
    skybake::render::Image image;
    image.width = v.width;
    image.height = v.height;
    image.rgb.resize(3 * pixels);
    for (std::size_t i = 0; i < pixels; ++i)
      for (int c = 0; c < 3; ++c) image.rgb[3 * i + c] = radiance[i][c];
    rendered.push_back(std::move(image));
  }
  WriteViews(args, luts, views, rendered);
}

}  // namespace

int main(int argc, char** argv) {
  return RunExample(argc, argv, "skybake_vulkan_example",
                    "Loads a baked set, uploads it to a headless Vulkan device and renders the fisheye sky and the "
                    "aerial view of the ground with the shipped GLSL snippet compiled to SPIR-V, to EXR and PNG.",
                    Run);
}
