// skybake_runtime_cost: what skybake's GLSL runtime costs per pixel, beside a
// peer's, on the drivers here (docs/runtime_cost.md).
//
//   skybake_runtime_cost --luts DIR [--peer DIR] [--size N] [--runs K] [--suns 30,80,...]
//                        [--no-hlsl] [--vulkan-entries sky,aerial,irradiance] [--json FILE] [--markdown FILE]
//
// --luts is a baked set (`skybake bake earth -o DIR`); the runtime measured
// is the one compiled into this tool (RuntimeSnippetSource), with the
// set's constants, sampling the set's tables. --peer is the folder of
// Bruneton's 2017 GLSL as @takram/three-atmosphere ships it
// (tests/runtime_cost/install_peer.mjs prints it); it samples the same tables,
// so its values mean nothing: only its cost is measured, in two variants
// (separate single Mie table, and COMBINED_SCATTERING_TEXTURES).
//
// For every case (sun zenith angle x sky from 1 m, sky from 10 km, aerial
// perspective from 300 m, ground irradiance) it
//   - counts per pixel, in a counting build of the fragment shader on OpenGL,
//     the texture fetches and transcendental functions each invocation
//     executes (mean and max over the N x N pixels);
//   - times full-screen N x N passes on OpenGL (llvmpipe) and as Vulkan
//     compute dispatches (lavapipe), K runs of each runtime in turn
//     (skybake, peer, peer combined, skybake, ...): medians and their ratios;
// and for each runtime and entry point it times glslang and the Vulkan
// pipeline creation and counts the SPIR-V instructions after `spirv-opt -O`
// (also for the shipped HLSL, through glslang's HLSL front end).
//
// Exit codes: 0 measured, 1 an error or a check failed (a count that cannot
// be zero is, a value is NaN, a shader does not compile), 77 skipped (no
// headless GL, Vulkan or glslangValidator).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "examples/engine/vulkan_compute.h"
#include "formats/lut_files.h"
#include "shaders_runtime/runtime.h"
#include "shaders_runtime/snippet.h"
#include "tests/gl_context.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

namespace fs = std::filesystem;
using testing::GlContext;
using testing::Vec4;

constexpr int kSkipped = 77;

enum class Entry { kSky, kAerial, kIrradiance };
constexpr Entry kEntries[] = {Entry::kSky, Entry::kAerial, Entry::kIrradiance};
const char* EntryName(Entry e) { return e == Entry::kSky ? "sky" : e == Entry::kAerial ? "aerial" : "irradiance"; }

// The small case of the untimed first draws and dispatches (8x8 pixels: 64
// invocations, one workgroup).
const Vec4 kWarmUpCase = {1.0f, 45.0f, 8.0f, 8.0f};

struct Options {
  fs::path luts;
  fs::path peer;  // empty: skybake only
  int size = 1024;
  int runs = 5;
  std::vector<double> suns = {30.0, 80.0, 88.0, 93.0, 98.0};
  bool hlsl = true;
  // The entry points compiled and timed on Vulkan (all: sky, aerial, irradiance).
  std::vector<Entry> vulkan_entries = {std::begin(kEntries), std::end(kEntries)};
  fs::path json;
  fs::path markdown;

  bool OnVulkan(Entry e) const {
    return std::find(vulkan_entries.begin(), vulkan_entries.end(), e) != vulkan_entries.end();
  }
};

// ---- the cases ----

struct Case {
  Entry entry;
  double altitude_m;  // of the camera (the point, for irradiance)
  double sun_zenith_deg;
  std::string name;
};

// Daylight suns, and those at sunset and in twilight, are grouped apart.
bool IsDaylight(double sun_zenith_deg) { return sun_zenith_deg < 85.0; }

std::string Degrees(double d) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g°", d);
  return buffer;
}

std::vector<Case> MakeCases(const std::vector<double>& suns) {
  std::vector<Case> cases;
  for (double sun : suns) {
    const std::string at = ", sun " + Degrees(sun);
    cases.push_back({Entry::kSky, 1.0, sun, "sky from 1 m" + at});
    cases.push_back({Entry::kSky, 10000.0, sun, "sky from 10 km" + at});
    cases.push_back({Entry::kAerial, 300.0, sun, "aerial perspective from 300 m" + at});
    cases.push_back({Entry::kIrradiance, 0.0, sun, "ground irradiance" + at});
  }
  return cases;
}

// ---- the shaders ----

// A GLSL float literal (GLSL ES converts no int to float implicitly).
std::string GlslFloat(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.9g", v);
  std::string s = buffer;
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

// The counting build's prelude: counters and wrappers of texture() (and
// textureLod, texelFetch) and the transcendental functions, then macros that
// route every later call through them. The wrappers come before the macros,
// so they call the built-ins. Counts are of calls the invocation executes, and
// of their scalar components (a vec4 log is 4).
std::string CountingPrelude() {
  std::string s =
      "// Counting build: the texture fetches and transcendental functions this invocation executes.\n"
      "int skybake_fetches = 0;\n"
      "int skybake_transcendental_calls = 0;\n"
      "int skybake_transcendental_scalars = 0;\n"
      "void skybake_reset_counts() {\n"
      "  skybake_fetches = 0;\n"
      "  skybake_transcendental_calls = 0;\n"
      "  skybake_transcendental_scalars = 0;\n"
      "}\n";
  for (const char* sampler : {"sampler2D", "sampler3D"}) {
    const std::string n = sampler[7] == '2' ? "2" : "3";
    const std::string t = std::string(sampler) + " s";
    s += "vec4 skybake_count_texture(" + t + ", vec" + n + " c) { skybake_fetches += 1; return texture(s, c); }\n";
    s += "vec4 skybake_count_textureLod(" + t + ", vec" + n +
         " c, float lod) { skybake_fetches += 1; return textureLod(s, c, lod); }\n";
    s += "vec4 skybake_count_texelFetch(" + t + ", ivec" + n +
         " c, int lod) { skybake_fetches += 1; return texelFetch(s, c, lod); }\n";
  }
  struct Function {
    const char* name;
    int arguments;
  };
  const Function functions[] = {{"exp", 1},  {"log", 1},  {"pow", 2},  {"sqrt", 1}, {"inversesqrt", 1},
                                {"exp2", 1}, {"log2", 1}, {"sin", 1},  {"cos", 1},  {"tan", 1},
                                {"asin", 1}, {"acos", 1}, {"atan", 1}, {"atan", 2}};
  const char* const types[] = {"float", "vec2", "vec3", "vec4"};
  for (const Function& f : functions) {
    for (int components = 1; components <= 4; ++components) {
      const std::string type = types[components - 1];
      const std::string parameters = f.arguments == 1 ? type + " x" : type + " x, " + type + " y";
      s += type + " skybake_count_" + f.name + "(" + parameters + ") { skybake_transcendental_calls += 1; " +
           "skybake_transcendental_scalars += " + std::to_string(components) + "; return " + f.name + "(" +
           (f.arguments == 1 ? "x" : "x, y") + "); }\n";
    }
  }
  // The fetches as object-like macros: skybake's runtime calls texture()
  // through `#define SampleTexture2D texture`, and Mesa's preprocessor
  // cannot expand a function-like macro whose name another macro's
  // expansion ends with. atan too: one or two arguments reach both overloads.
  s += "#define texture skybake_count_texture\n"
       "#define textureLod skybake_count_textureLod\n"
       "#define texelFetch skybake_count_texelFetch\n"
       "#define atan skybake_count_atan\n"
       "#define pow(x, y) skybake_count_pow(x, y)\n";
  for (const Function& f : functions) {
    if (f.arguments == 1 && std::string(f.name) != "atan")
      s += std::string("#define ") + f.name + "(x) skybake_count_" + f.name + "(x)\n";
  }
  return s;
}

// One runtime as the cost shader calls it: its GLSL (no #version line), and
// CostSky, CostAerial and CostIrradiance, which call its entry points with
// positions in its length unit (COST_LENGTH_UNIT metres).
struct Runtime {
  std::string name;         // in the JSON
  std::string description;  // in the tables
  std::string glsl;
};

// The entry points' adapters for skybake's runtime: metres, the signatures
// of shaders_runtime/README.md.
constexpr char kSkybakeAdapters[] = R"(
const float COST_LENGTH_UNIT = 1.0;  // positions in metres
vec3 CostSky(vec3 camera, vec3 view_ray, vec3 sun_direction, out vec3 transmittance) {
  return GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                        camera, view_ray, sun_direction, transmittance);
}
vec3 CostAerial(vec3 camera, vec3 point, vec3 sun_direction, out vec3 transmittance) {
  return GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture,
                               single_mie_scattering_texture, camera, point, sun_direction, transmittance);
}
vec3 CostIrradiance(vec3 point, vec3 normal, vec3 sun_direction, out vec3 sky_irradiance) {
  return GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, point, normal,
                                sun_direction, sky_irradiance);
}
)";

// The entry points' adapters for skybake's per-frame path
// (shaders_runtime/per_frame.glsl): the sky read from a sky view, aerial
// perspective from a volume (at a screen position taken from the ray's
// direction), irradiance as the direct lookup (it has no per-frame table).
// The per-frame tables are the set's own tables under their names (a 2D and
// a 3D table, read at the same coordinates): only the cost is measured, and
// the tables of a frame, smaller than these, would be read faster if at all
// differently.
constexpr char kSkybakePerFrameAdapters[] = R"(
#define sky_view_texture transmittance_texture
#define aerial_perspective_radiance scattering_texture
#define aerial_perspective_optical_depth single_mie_scattering_texture
const float COST_LENGTH_UNIT = 1.0;  // positions in metres
vec3 CostSky(vec3 camera, vec3 view_ray, vec3 sun_direction, out vec3 transmittance) {
  return GetSkyRadianceFromSkyView(ATMOSPHERE, transmittance_texture, sky_view_texture, camera, view_ray,
                                   sun_direction, transmittance);
}
vec3 CostAerial(vec3 camera, vec3 point, vec3 sun_direction, out vec3 transmittance) {
  vec3 to_point = point - camera;
  vec2 screen_uv = normalize(to_point).xy * 0.5 + 0.5;
  return GetSkyRadianceToPointFromVolume(aerial_perspective_radiance, aerial_perspective_optical_depth,
                                         screen_uv, length(to_point), transmittance);
}
vec3 CostIrradiance(vec3 point, vec3 normal, vec3 sun_direction, out vec3 sky_irradiance) {
  return GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, point, normal,
                                sun_direction, sky_irradiance);
}
)";

// The peer's adapters: its ATMOSPHERE is in kilometres (three-atmosphere's
// METER_TO_LENGTH_UNIT), and its GetSkyRadiance and GetSkyRadianceToPoint
// take a shadow length (0: no light shafts).
constexpr char kPeerAdapters[] = R"(
const float COST_LENGTH_UNIT = 1000.0;  // positions in kilometres
vec3 CostSky(vec3 camera, vec3 view_ray, vec3 sun_direction, out vec3 transmittance) {
  return GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                        camera, view_ray, 0.0, sun_direction, transmittance);
}
vec3 CostAerial(vec3 camera, vec3 point, vec3 sun_direction, out vec3 transmittance) {
  return GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture,
                               single_mie_scattering_texture, camera, point, 0.0, sun_direction, transmittance);
}
vec3 CostIrradiance(vec3 point, vec3 normal, vec3 sun_direction, out vec3 sky_irradiance) {
  return GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, point, normal,
                                sun_direction, sky_irradiance);
}
)";

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

Runtime SkybakeRuntime(const LutSet& luts, bool per_frame) {
  SnippetParts parts;
  parts.channels_are_xyz = luts.colour.has_value();
  return {per_frame ? "skybake_per_frame" : "skybake", per_frame ? "skybake, per-frame tables" : "skybake",
          RuntimeSnippetSource(ShadingLanguage::kGlsl, luts.parameters, luts.atmosphere.wavelengths_nm,
                               luts.atmosphere.name, parts) +
              (per_frame ? kSkybakePerFrameAdapters : kSkybakeAdapters)};
}

// Bruneton's runtime from `peer_dir` with what it leaves to its host: the
// tables' sizes (those of `luts`, which it samples), the GROUND switch
// (three-atmosphere's name for Bruneton's ground test in GetSkyRadiance), the
// constant ATMOSPHERE with Bruneton's Earth (his demo's values, in
// kilometres, on the set's radii and lowest sun) and the luminance factors
// its unused GetSky*Luminance wrappers read. The radiance-named macros it
// ends with (GetSkyRadiance -> GetSkyLuminance, ...) are undone, so that the
// adapters call the radiance functions, as skybake's are called.
Runtime PeerRuntime(const fs::path& peer_dir, const LutSet& luts, bool combined) {
  const glsl::AtmosphereParameters& p = luts.parameters;
  if (p.scattering_nu_size * p.scattering_mu_s_size != luts.scattering.width)
    throw std::runtime_error("the set's scattering table is not nu x mu_s columns wide");
  const double km = 1000.0;
  std::ostringstream s;
  s << "// Bruneton's 2017 runtime as @takram/three-atmosphere ships it, on the measured set's tables.\n";
  if (combined) s << "#define COMBINED_SCATTERING_TEXTURES\n";
  s << "#define GROUND\n"
    << "#define TRANSMITTANCE_TEXTURE_WIDTH " << luts.transmittance.width << "\n"
    << "#define TRANSMITTANCE_TEXTURE_HEIGHT " << luts.transmittance.height << "\n"
    << "#define SCATTERING_TEXTURE_R_SIZE " << luts.scattering.depth << "\n"
    << "#define SCATTERING_TEXTURE_MU_SIZE " << luts.scattering.height << "\n"
    << "#define SCATTERING_TEXTURE_MU_S_SIZE " << p.scattering_mu_s_size << "\n"
    << "#define SCATTERING_TEXTURE_NU_SIZE " << p.scattering_nu_size << "\n"
    << "#define IRRADIANCE_TEXTURE_WIDTH " << luts.irradiance.width << "\n"
    << "#define IRRADIANCE_TEXTURE_HEIGHT " << luts.irradiance.height << "\n";
  s << ReadFile(peer_dir / "definitions.glsl") << "\n";
  // Bruneton's demo atmosphere (atmosphere/demo/demo.cc), per kilometre:
  // Rayleigh 5.802, 13.558, 33.1 per 1e6 m with an 8 km scale height; Mie
  // scattering 3.996, extinction 4.44 per 1e6 m, 1.2 km scale height,
  // g = 0.8; ozone 0.65, 1.881, 0.085 per 1e6 m in a tent peaking at 25 km.
  s << "const AtmosphereParameters ATMOSPHERE = AtmosphereParameters(\n"
    << "    vec3(1.474, 1.8504, 1.91198), 0.004675, " << GlslFloat(p.bottom_radius / km) << ", "
    << GlslFloat(p.top_radius / km) << ",\n"
    << "    DensityProfile(DensityProfileLayer[2](DensityProfileLayer(0.0, 0.0, 0.0, 0.0, 0.0),\n"
    << "                                          DensityProfileLayer(0.0, 1.0, -0.125, 0.0, 0.0))),\n"
    << "    vec3(0.005802, 0.013558, 0.0331),\n"
    << "    DensityProfile(DensityProfileLayer[2](DensityProfileLayer(0.0, 0.0, 0.0, 0.0, 0.0),\n"
    << "                                          DensityProfileLayer(0.0, 1.0, -0.833333, 0.0, 0.0))),\n"
    << "    vec3(0.003996), vec3(0.00444), 0.8,\n"
    << "    DensityProfile(DensityProfileLayer[2](DensityProfileLayer(25.0, 0.0, 0.0, 1.0 / 15.0, -2.0 / 3.0),\n"
    << "                                          DensityProfileLayer(0.0, 0.0, 0.0, -1.0 / 15.0, 8.0 / 3.0))),\n"
    << "    vec3(0.00065, 0.001881, 0.000085), vec3(0.1), " << GlslFloat(p.mu_s_min) << ");\n"
    << "const vec3 SKY_SPECTRAL_RADIANCE_TO_LUMINANCE = vec3(114974.916437, 71305.954816, 65310.548555);\n"
    << "const vec3 SUN_SPECTRAL_RADIANCE_TO_LUMINANCE = vec3(98242.786222, 69954.398112, 66475.012354);\n";
  s << ReadFile(peer_dir / "common.glsl") << "\n" << ReadFile(peer_dir / "runtime.glsl") << "\n";
  s << "#undef GetSolarRadiance\n#undef GetSkyRadiance\n#undef GetSkyRadianceToPoint\n"
       "#undef GetSunAndSkyIrradiance\n#undef GetSunAndSkyScalarIrradiance\n";
  s << kPeerAdapters;
  return {combined ? "peer_combined" : "peer_separate",
          combined ? "Bruneton 2017, combined" : "Bruneton 2017, separate single Mie", s.str()};
}

// CostPixel(pixel, view_case): one pixel of a case, view_case = (camera
// altitude in metres, sun zenith in degrees, width, height). The views, in
// metres from the planet centre, camera on the z axis, sun in the x-z plane:
//   sky, irradiance: pixel (i, j) looks (normal: faces) azimuth (i + 0.5) / W
//     * 360 degrees from the sun, zenith (j + 0.5) / H * 180 degrees;
//   aerial: azimuth likewise; distance 0.1 km * 500^t, t = (j + 0.5) / (H / 2)
//     in each half of the rows: in the first half to a point on the ground
//     that far along the ground, in the second to a point that far along view
//     zenith 87 degrees.
// Only the runtime's calls are counted (counters reset just before them).
std::string CostBody(Entry entry, double bottom_radius_m, bool counting) {
  std::string s = "#define COST_ENTRY " + std::to_string(static_cast<int>(entry)) + "\n" +
                  "const float COST_BOTTOM_RADIUS_M = " + GlslFloat(bottom_radius_m) + ";\n";
  s += R"(
const float COST_PI = 3.14159265358979;
vec4 CostPixel(ivec2 pixel, vec4 view_case) {
  vec2 f = (vec2(pixel) + 0.5) / view_case.zw;
  float azimuth = f.x * 2.0 * COST_PI;
  float sun_zenith = radians(view_case.y);
  vec3 sun_direction = vec3(sin(sun_zenith), 0.0, cos(sun_zenith));
  vec3 camera = vec3(0.0, 0.0, COST_BOTTOM_RADIUS_M + view_case.x);
#if COST_ENTRY == 1
  bool on_ground = f.y < 0.5;
  float distance = 100.0 * pow(500.0, on_ground ? 2.0 * f.y : 2.0 * f.y - 1.0);
  vec3 point;
  if (on_ground) {
    float angle = distance / COST_BOTTOM_RADIUS_M;
    point = COST_BOTTOM_RADIUS_M * vec3(sin(angle) * cos(azimuth), sin(angle) * sin(azimuth), cos(angle));
  } else {
    float zenith = radians(87.0);
    point = camera + distance * vec3(sin(zenith) * cos(azimuth), sin(zenith) * sin(azimuth), cos(zenith));
  }
#else
  float zenith = f.y * COST_PI;
  vec3 direction = vec3(sin(zenith) * cos(azimuth), sin(zenith) * sin(azimuth), cos(zenith));
#endif
  vec3 radiance, second;
)";
  if (counting) s += "  skybake_reset_counts();\n";
  s += R"(#if COST_ENTRY == 0
  radiance = CostSky(camera / COST_LENGTH_UNIT, direction, sun_direction, second);
#elif COST_ENTRY == 1
  radiance = CostAerial(camera / COST_LENGTH_UNIT, point / COST_LENGTH_UNIT, sun_direction, second);
#else
  radiance = CostIrradiance(camera / COST_LENGTH_UNIT, direction, sun_direction, second);
#endif
)";
  s += counting ? "  return vec4(float(skybake_fetches), float(skybake_transcendental_calls),\n"
                  "              float(skybake_transcendental_scalars), dot(radiance + second, vec3(1.0)));\n}\n"
                : "  return vec4(radiance, dot(second, vec3(1.0 / 3.0)));\n}\n";
  return s;
}

constexpr char kGlTables[] =
    "uniform sampler2D transmittance_texture;\n"
    "uniform sampler3D scattering_texture;\n"
    "uniform sampler3D single_mie_scattering_texture;\n"
    "uniform sampler2D irradiance_texture;\n";

constexpr char kGlMain[] = R"(
uniform vec4 cost_case;
void main() { skybake_output = CostPixel(ivec2(gl_FragCoord.xy), cost_case); }
)";

constexpr char kVulkanMain[] = R"(
layout(std430, set = 0, binding = 4) readonly buffer Inputs { vec4 cost_inputs[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Outputs { vec4 cost_outputs[]; };
layout(local_size_x = 64) in;
void main() {
  int item = int(gl_GlobalInvocationID.x);
  if (item >= cost_outputs.length()) return;
  vec4 view_case = cost_inputs[0];
  int width = int(view_case.z);
  cost_outputs[item] = CostPixel(ivec2(item % width, item / width), view_case);
}
)";

// The fragment shader (after GlContext's prologue) of one runtime and entry point.
std::string GlShader(const Runtime& runtime, Entry entry, double bottom_radius_m, bool counting) {
  return std::string(kGlTables) + (counting ? CountingPrelude() : "") + runtime.glsl +
         CostBody(entry, bottom_radius_m, counting) + kGlMain;
}

std::string VulkanShader(const Runtime& runtime, Entry entry, double bottom_radius_m) {
  return "#version 450\n" + std::string(VulkanCompute::kGlslTables) + runtime.glsl +
         CostBody(entry, bottom_radius_m, false) + kVulkanMain;
}

// The shipped HLSL's compute shader of the same views (sky and aerial only:
// it is compiled, not timed).
std::string HlslShader(const LutSet& luts, Entry entry) {
  SnippetParts parts;
  parts.channels_are_xyz = luts.colour.has_value();
  std::string s = RuntimeSnippetSource(ShadingLanguage::kHlsl, luts.parameters, luts.atmosphere.wavelengths_nm,
                                       luts.atmosphere.name, parts);
  s += "#define COST_ENTRY " + std::to_string(static_cast<int>(entry)) + "\n" +
       "static const float COST_BOTTOM_RADIUS_M = " + GlslFloat(luts.parameters.bottom_radius) + ";\n";
  s += R"(
[[vk::binding(0)]] Texture2D<float4> transmittance_texture;
[[vk::binding(1)]] Texture3D<float4> scattering_texture;
[[vk::binding(2)]] Texture3D<float4> single_mie_scattering_texture;
[[vk::binding(3)]] Texture2D<float4> irradiance_texture;
[[vk::binding(4)]] StructuredBuffer<float4> cost_inputs;
[[vk::binding(5)]] RWStructuredBuffer<float4> cost_outputs;
[[vk::binding(6)]] SamplerState linear_sampler;
[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint count, stride;
  cost_outputs.GetDimensions(count, stride);
  if (id.x >= count) return;
  float4 view_case = cost_inputs[0];
  uint width = uint(view_case.z);
  float2 f = (float2(id.x % width, id.x / width) + 0.5) / view_case.zw;
  float azimuth = f.x * 2.0 * 3.14159265358979;
  float sun_zenith = radians(view_case.y);
  float3 sun_direction = float3(sin(sun_zenith), 0.0, cos(sun_zenith));
  float3 camera = float3(0.0, 0.0, COST_BOTTOM_RADIUS_M + view_case.x);
  AtmosphereParameters atmosphere = ATMOSPHERE;
  float3 radiance, transmittance;
#if COST_ENTRY == 1
  bool on_ground = f.y < 0.5;
  float distance = 100.0 * pow(500.0, on_ground ? 2.0 * f.y : 2.0 * f.y - 1.0);
  float3 target;  // `point` is an HLSL keyword
  if (on_ground) {
    float angle = distance / COST_BOTTOM_RADIUS_M;
    target = COST_BOTTOM_RADIUS_M * float3(sin(angle) * cos(azimuth), sin(angle) * sin(azimuth), cos(angle));
  } else {
    float zenith = radians(87.0);
    target = camera + distance * float3(sin(zenith) * cos(azimuth), sin(zenith) * sin(azimuth), cos(zenith));
  }
  radiance = GetSkyRadianceToPoint(atmosphere, transmittance_texture, linear_sampler, scattering_texture,
                                   linear_sampler, single_mie_scattering_texture, linear_sampler, camera, target,
                                   sun_direction, transmittance);
#else
  float zenith = f.y * 3.14159265358979;
  float3 direction = float3(sin(zenith) * cos(azimuth), sin(zenith) * sin(azimuth), cos(zenith));
  radiance = GetSkyRadiance(atmosphere, transmittance_texture, linear_sampler, scattering_texture, linear_sampler,
                            single_mie_scattering_texture, linear_sampler, camera, direction, sun_direction,
                            transmittance);
#endif
  cost_outputs[id.x] = float4(radiance, dot(transmittance, float3(1.0, 1.0, 1.0) / 3.0));
}
)";
  return s;
}

// ---- SPIR-V ----

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Instructions in a SPIR-V module (after the five header words, each
// instruction's first word holds its word count in the high half).
int InstructionCount(const std::vector<std::uint32_t>& words) {
  int count = 0;
  for (size_t i = 5; i < words.size(); ++count) {
    const std::uint32_t length = words[i] >> 16;
    if (length == 0) throw std::runtime_error("malformed SPIR-V");
    i += length;
  }
  return count;
}

// The instruction count of `spirv` after `spirv-opt -O`; -1 without spirv-opt.
int OptimizedInstructionCount(const std::vector<std::uint32_t>& spirv) {
  if (std::string(SKYBAKE_SPIRV_OPT).empty()) return -1;
  testing::TempDir dir;
  const fs::path in = dir.path() / "shader.spv", out = dir.path() / "optimized.spv";
  {
    std::ofstream file(in, std::ios::binary);
    file.write(reinterpret_cast<const char*>(spirv.data()), std::streamsize(spirv.size() * 4));
  }
  std::string log;
  if (testing::RunCommand(
          testing::ShellQuote(SKYBAKE_SPIRV_OPT) + " -O " + testing::ShellQuote(in) + " -o " + testing::ShellQuote(out),
          dir, nullptr, &log) != 0) {
    throw std::runtime_error("spirv-opt -O failed:\n" + log);
  }
  const std::string bytes = ReadFile(out);
  std::vector<std::uint32_t> words(bytes.size() / 4);
  std::copy(bytes.begin(), bytes.begin() + std::ptrdiff_t(words.size() * 4), reinterpret_cast<char*>(words.data()));
  return InstructionCount(words);
}

struct CompiledShader {
  std::string runtime;   // Runtime::name
  std::string language;  // "Vulkan GLSL 4.50" or "HLSL"
  Entry entry = Entry::kSky;
  std::vector<std::uint32_t> spirv;
  double glslang_seconds = 0.0;
  double pipeline_seconds = 0.0;
  double first_dispatch_seconds = 0.0;  // 64 invocations, right after the creation
  int pipeline = -1;                    // VulkanCompute::CreatePipeline's index
  int instructions = 0;
  int optimized_instructions = -1;
};

CompiledShader CompileForVulkan(VulkanCompute* vk, const std::string& runtime, const std::string& source, bool hlsl,
                                Entry entry) {
  CompiledShader c;
  c.runtime = runtime;
  c.language = hlsl ? "HLSL" : "Vulkan GLSL 4.50";
  c.entry = entry;
  std::string log;
  const auto start = std::chrono::steady_clock::now();
  c.spirv = CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, source, hlsl, &log);
  c.glslang_seconds = SecondsSince(start);
  if (c.spirv.empty())
    throw std::runtime_error(runtime + " " + EntryName(entry) + " (" + c.language + ") does not compile:\n" + log);
  c.pipeline = vk->CreatePipeline(
      c.spirv, hlsl ? VulkanCompute::Samplers::kSeparate : VulkanCompute::Samplers::kCombined, &c.pipeline_seconds);
  // lavapipe may leave part of the compile to the first dispatch.
  c.first_dispatch_seconds = vk->TimeDispatch(c.pipeline, {kWarmUpCase}, 64, nullptr);
  c.instructions = InstructionCount(c.spirv);
  c.optimized_instructions = OptimizedInstructionCount(c.spirv);
  return c;
}

// ---- measuring ----

struct Statistic {
  double mean = 0.0;
  double max = 0.0;
};

struct Counts {
  Statistic fetches, calls, scalars;
  bool counts_whole = true;     // every count a finite whole number
  bool radiance_finite = true;  // every pixel's radiance and second output finite
};

Counts Summarize(const std::vector<Vec4>& pixels) {
  Counts c;
  Statistic* stats[] = {&c.fetches, &c.calls, &c.scalars};
  for (const Vec4& p : pixels) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(p[k]) || p[k] < 0.0f || p[k] != std::floor(p[k])) c.counts_whole = false;
      stats[k]->mean += p[k];
      stats[k]->max = std::max(stats[k]->max, double(p[k]));
    }
    if (!std::isfinite(p[3])) c.radiance_finite = false;
  }
  for (Statistic* s : stats) s->mean /= double(pixels.size());
  return c;
}

// NaN for no values (a driver that did not run the case).
double Median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct RuntimeResult {
  Counts counts;
  std::vector<double> gl_seconds, vulkan_seconds;
};

struct CaseResult {
  Case c;
  std::vector<RuntimeResult> runtimes;  // as Measurement::runtimes
};

// The index of the peer's first runtime in Measurement::runtimes.
constexpr size_t kFirstPeer = 2;

struct Measurement {
  std::vector<Runtime> runtimes;  // skybake, its per-frame path, then the peer's two (kFirstPeer)
  std::string gl_driver, gl_es_driver, vulkan_driver;
  std::vector<CompiledShader> shaders;
  std::vector<CaseResult> cases;
  int size = 0, runs = 0;
};

const CompiledShader* FindShader(const Measurement& m, const std::string& runtime, const std::string& language,
                                 Entry entry) {
  for (const CompiledShader& s : m.shaders)
    if (s.runtime == runtime && s.language == language && s.entry == entry) return &s;
  return nullptr;
}

// The set's tables on `gl` and `vk` (either may be null); a set with single
// Mie packed into alpha has no single Mie table: the scattering table stands in.
void SetTables(GlContext* gl, VulkanCompute* vk, const LutSet& luts) {
  const glsl::Texture& mie = luts.single_mie_scattering.empty() ? luts.scattering : luts.single_mie_scattering;
  const std::pair<const char*, const glsl::Texture*> tables[] = {{"transmittance_texture", &luts.transmittance},
                                                                 {"scattering_texture", &luts.scattering},
                                                                 {"single_mie_scattering_texture", &mie},
                                                                 {"irradiance_texture", &luts.irradiance}};
  for (int binding = 0; binding < 4; ++binding) {
    const glsl::Texture& t = *tables[binding].second;
    if (gl) gl->SetTexture(tables[binding].first, t.width, t.height, t.depth, t.texels.data(), t.texels.size());
    if (vk) vk->SetTexture(binding, t.width, t.height, t.depth, t.texels.data(), t.texels.size());
  }
}

Vec4 ViewCase(const Case& c, int size) {
  return {float(c.altitude_m), float(c.sun_zenith_deg), float(size), float(size)};
}

std::vector<Runtime> Runtimes(const Options& options, const LutSet& luts) {
  std::vector<Runtime> runtimes = {SkybakeRuntime(luts, false), SkybakeRuntime(luts, true)};
  if (!options.peer.empty()) {
    runtimes.push_back(PeerRuntime(options.peer, luts, false));
    runtimes.push_back(PeerRuntime(options.peer, luts, true));
  }
  return runtimes;
}

// The counting build of every runtime and entry point compiles and runs on
// `gl_es` (OpenGL ES 3.0) as well; throws if not.
void CheckCountingBuild(GlContext* gl_es, const std::vector<Runtime>& runtimes, const LutSet& luts) {
  SetTables(gl_es, nullptr, luts);
  for (const Runtime& runtime : runtimes) {
    for (Entry e : kEntries) {
      std::cerr << "compiling the counting build of " << runtime.name << " " << EntryName(e) << " for "
                << gl_es->VersionLine() << "\n";
      const unsigned program =
          gl_es->CompileFullScreenProgram(GlShader(runtime, e, luts.parameters.bottom_radius, true));
      gl_es->RenderFullScreen(program, 8, 8, {{"cost_case", kWarmUpCase}}, nullptr);
    }
  }
}

// Everything but the ES check, on `gl` (one context is current at a time:
// GlContext does not switch) and `vk`.
Measurement Measure(const Options& options, const LutSet& luts, std::vector<Runtime> runtimes, GlContext* gl,
                    VulkanCompute* vk) {
  Measurement m;
  m.size = options.size;
  m.runs = options.runs;
  m.gl_driver = gl->Description();
  m.vulkan_driver = vk->Description();
  m.runtimes = std::move(runtimes);
  const double radius = luts.parameters.bottom_radius;
  const int n = options.size;
  SetTables(gl, vk, luts);

  // Every program and pipeline, compiled once, then drawn once untimed
  // (llvmpipe and lavapipe finish compiling at the first draw).
  std::map<std::pair<size_t, Entry>, unsigned> gl_counting, gl_timing;
  std::map<std::pair<size_t, Entry>, int> vulkan;
  for (size_t r = 0; r < m.runtimes.size(); ++r) {
    for (Entry e : kEntries) {
      std::cerr << "compiling " << m.runtimes[r].name << " " << EntryName(e) << "\n";
      gl_counting[{r, e}] = gl->CompileFullScreenProgram(GlShader(m.runtimes[r], e, radius, true));
      gl_timing[{r, e}] = gl->CompileFullScreenProgram(GlShader(m.runtimes[r], e, radius, false));
      for (unsigned program : {gl_counting[{r, e}], gl_timing[{r, e}]})
        gl->RenderFullScreen(program, 8, 8, {{"cost_case", kWarmUpCase}}, nullptr);
      if (!options.OnVulkan(e)) continue;
      m.shaders.push_back(CompileForVulkan(vk, m.runtimes[r].name, VulkanShader(m.runtimes[r], e, radius), false, e));
      vulkan[{r, e}] = m.shaders.back().pipeline;
    }
  }
  if (options.hlsl) {
    for (Entry e : {Entry::kSky, Entry::kAerial}) {
      if (!options.OnVulkan(e)) continue;
      std::cerr << "compiling skybake HLSL " << EntryName(e) << "\n";
      m.shaders.push_back(CompileForVulkan(vk, "skybake", HlslShader(luts, e), true, e));
    }
  }

  for (const Case& c : MakeCases(options.suns)) {
    std::cerr << c.name << "\n";
    CaseResult result{c, std::vector<RuntimeResult>(m.runtimes.size())};
    const Vec4 view_case = ViewCase(c, n);
    for (size_t r = 0; r < m.runtimes.size(); ++r) {
      std::vector<Vec4> pixels;
      gl->RenderFullScreen(gl_counting[{r, c.entry}], n, n, {{"cost_case", view_case}}, &pixels);
      result.runtimes[r].counts = Summarize(pixels);
    }
    // Runs alternate between the runtimes, so that a change in the machine's
    // load falls on all of them alike.
    for (int k = 0; k < options.runs; ++k) {
      for (size_t r = 0; r < m.runtimes.size(); ++r) {
        result.runtimes[r].gl_seconds.push_back(
            gl->RenderFullScreen(gl_timing[{r, c.entry}], n, n, {{"cost_case", view_case}}, nullptr));
      }
    }
    for (int k = 0; k < options.runs && vulkan.count({0, c.entry}); ++k) {
      for (size_t r = 0; r < m.runtimes.size(); ++r) {
        result.runtimes[r].vulkan_seconds.push_back(
            vk->TimeDispatch(vulkan[{r, c.entry}], {view_case}, size_t(n) * n, nullptr));
      }
    }
    m.cases.push_back(std::move(result));
  }
  return m;
}

// What cannot be: a runtime that fetches nothing or calls no transcendental
// function (every entry point of both runtimes takes a square root at
// least), counts that are not whole numbers, skybake radiance that is NaN or
// infinite (the peer's values, from tables of another layout, mean nothing),
// times that are not positive, SPIR-V without instructions.
std::vector<std::string> Check(const Measurement& m) {
  std::vector<std::string> failures;
  for (const CaseResult& c : m.cases) {
    for (size_t r = 0; r < m.runtimes.size(); ++r) {
      const RuntimeResult& result = c.runtimes[r];
      const std::string where = m.runtimes[r].name + ", " + c.c.name + ": ";
      const Counts& counts = result.counts;
      if (!counts.counts_whole) failures.push_back(where + "a count is not a whole number");
      if (!(counts.fetches.mean > 0.0)) failures.push_back(where + "no texture fetches");
      if (!(counts.calls.mean > 0.0)) failures.push_back(where + "no transcendental functions");
      if (!(counts.scalars.mean >= counts.calls.mean)) failures.push_back(where + "fewer scalars than calls");
      if (r == 0 && !counts.radiance_finite) failures.push_back(where + "radiance is NaN or infinite");
      for (const std::vector<double>* times : {&result.gl_seconds, &result.vulkan_seconds}) {
        for (double t : *times)
          if (!(t > 0.0) || !std::isfinite(t)) failures.push_back(where + "a time is not positive");
      }
    }
  }
  for (const CompiledShader& s : m.shaders) {
    if (s.instructions <= 0 || s.optimized_instructions == 0)
      failures.push_back(s.runtime + " " + EntryName(s.entry) + ": no SPIR-V instructions");
  }
  return failures;
}

// ---- reporting ----

nlohmann::ordered_json StatisticJson(const Statistic& s) { return {{"mean", s.mean}, {"max", s.max}}; }

nlohmann::ordered_json ToJson(const Measurement& m, const Options& options) {
  nlohmann::ordered_json j;
  j["luts"] = options.luts.string();
  j["peer"] = options.peer.string();
  j["size"] = m.size;
  j["runs"] = m.runs;
  j["gl_driver"] = m.gl_driver;
  j["gl_es_driver"] = m.gl_es_driver;
  j["vulkan_driver"] = m.vulkan_driver;
  j["runtimes"] = nlohmann::ordered_json::array();
  for (const Runtime& r : m.runtimes) j["runtimes"].push_back({{"name", r.name}, {"description", r.description}});
  j["shaders"] = nlohmann::ordered_json::array();
  for (const CompiledShader& s : m.shaders) {
    j["shaders"].push_back({{"runtime", s.runtime},
                            {"language", s.language},
                            {"entry", EntryName(s.entry)},
                            {"glslang_seconds", s.glslang_seconds},
                            {"pipeline_seconds", s.pipeline_seconds},
                            {"first_dispatch_seconds", s.first_dispatch_seconds},
                            {"spirv_instructions", s.instructions},
                            {"spirv_instructions_optimized", s.optimized_instructions}});
  }
  j["cases"] = nlohmann::ordered_json::array();
  for (const CaseResult& c : m.cases) {
    nlohmann::ordered_json jc = {{"name", c.c.name},
                                 {"entry", EntryName(c.c.entry)},
                                 {"altitude_m", c.c.altitude_m},
                                 {"sun_zenith_deg", c.c.sun_zenith_deg}};
    for (size_t r = 0; r < m.runtimes.size(); ++r) {
      const RuntimeResult& result = c.runtimes[r];
      jc[m.runtimes[r].name] = {{"fetches", StatisticJson(result.counts.fetches)},
                                {"transcendental_calls", StatisticJson(result.counts.calls)},
                                {"transcendental_scalars", StatisticJson(result.counts.scalars)},
                                {"gl_seconds", result.gl_seconds},
                                {"gl_median_seconds", Median(result.gl_seconds)}};
      if (r > 0) jc[m.runtimes[r].name]["gl_ratio"] = Median(c.runtimes[0].gl_seconds) / Median(result.gl_seconds);
      if (!result.vulkan_seconds.empty()) {
        jc[m.runtimes[r].name]["vulkan_seconds"] = result.vulkan_seconds;
        jc[m.runtimes[r].name]["vulkan_median_seconds"] = Median(result.vulkan_seconds);
        if (r > 0) {
          jc[m.runtimes[r].name]["vulkan_ratio"] = Median(c.runtimes[0].vulkan_seconds) / Median(result.vulkan_seconds);
        }
      }
    }
    j["cases"].push_back(jc);
  }
  return j;
}

std::string Format(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// "a" or "a–b" over the values, each with `format`.
std::string Range(const std::vector<double>& values, const char* format) {
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  const std::string a = Format(format, *lo), b = Format(format, *hi);
  return a == b ? a : a + "–" + b;
}

std::string Ratio(double r) { return "×" + Format(r < 10.0 ? "%.1f" : "%.0f", r); }

std::string RatioRange(const std::vector<double>& values) {
  if (std::any_of(values.begin(), values.end(), [](double v) { return std::isnan(v); })) return "—";
  const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
  return Ratio(*lo) == Ratio(*hi) ? Ratio(*lo) : Ratio(*lo) + "–" + Ratio(*hi).substr(std::string("×").size());
}

std::string Markdown(const Measurement& m) {
  const bool peer = m.runtimes.size() > kFirstPeer;
  struct Group {
    std::string name;
    std::vector<const CaseResult*> cases;
    Entry entry;
  };
  // The case groups: each entry point, daylight suns apart from the others.
  std::vector<Group> groups;
  const char* const entry_titles[] = {"sky", "aerial perspective (0.1–50 km from 300 m)", "ground irradiance"};
  for (Entry e : kEntries) {
    for (bool daylight : {true, false}) {
      Group g{"", {}, e};
      std::vector<double> suns;
      for (const CaseResult& c : m.cases) {
        if (c.c.entry == e && IsDaylight(c.c.sun_zenith_deg) == daylight) {
          g.cases.push_back(&c);
          if (std::find(suns.begin(), suns.end(), c.c.sun_zenith_deg) == suns.end()) suns.push_back(c.c.sun_zenith_deg);
        }
      }
      if (g.cases.empty()) continue;
      std::string sun_text;
      for (double s : suns) sun_text += (sun_text.empty() ? "" : ", ") + Format("%g", s);
      g.name = std::string(entry_titles[int(e)]) + (daylight ? ", daylight" : ", sunset and twilight") + " (sun " +
               sun_text + "°)";
      groups.push_back(g);
    }
  }
  auto values = [](const Group& g, auto of) {
    std::vector<double> v;
    for (const CaseResult* c : g.cases) v.push_back(of(*c));
    return v;
  };
  auto instructions = [&](const std::string& runtime, const std::string& language, Entry e) {
    const CompiledShader* s = FindShader(m, runtime, language, e);
    return s && s->optimized_instructions > 0 ? std::to_string(s->optimized_instructions) : std::string("—");
  };

  // The ratios of runtime `of`'s median times in group g to the peer's
  // (separate / combined), on GL or Vulkan.
  auto peer_ratios = [&](const Group& g, size_t of, bool vulkan) {
    if (!peer) return std::string("—");
    std::string cell;
    for (size_t r = kFirstPeer; r < m.runtimes.size(); ++r) {
      cell += (r > kFirstPeer ? " / " : "") + RatioRange(values(g, [&](const CaseResult& c) {
                auto median = [&](size_t k) {
                  return Median(vulkan ? c.runtimes[k].vulkan_seconds : c.runtimes[k].gl_seconds);
                };
                return median(of) / median(r);
              }));
    }
    return cell;
  };

  std::ostringstream out;
  out << "Per pixel, " << m.size << "×" << m.size << " pixels per case; counts are means over the pixels (the "
      << "largest in brackets) and, for a group, the range of its cases' means. Peer: "
      << (peer ? "separate single Mie / combined" : "not measured") << ". Times: medians of " << m.runs
      << " alternating runs, the ratio skybake / peer.\n\n";
  out << "| case group | texture fetches: skybake | peer | transcendental calls: skybake | peer "
         "| SPIR-V instructions after `spirv-opt -O`: skybake | peer | time on llvmpipe (GL), ratio "
         "| time on lavapipe (Vulkan compute), ratio |\n"
         "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const Group& g : groups) {
    auto count_cell = [&](size_t r, const Statistic Counts::*statistic) {
      std::vector<double> maxima =
          values(g, [&](const CaseResult& c) { return (c.runtimes[r].counts.*statistic).max; });
      return Range(values(g, [&](const CaseResult& c) { return (c.runtimes[r].counts.*statistic).mean; }), "%.1f") +
             " (" + Format("%.0f", *std::max_element(maxima.begin(), maxima.end())) + ")";
    };
    auto peer_cells = [&](const Statistic Counts::*statistic) {
      return peer ? count_cell(kFirstPeer, statistic) + " / " + count_cell(kFirstPeer + 1, statistic)
                  : std::string("—");
    };
    out << "| " << g.name << " | " << count_cell(0, &Counts::fetches) << " | " << peer_cells(&Counts::fetches) << " | "
        << count_cell(0, &Counts::calls) << " | " << peer_cells(&Counts::calls) << " | "
        << instructions("skybake", "Vulkan GLSL 4.50", g.entry) << " | "
        << (peer ? instructions("peer_separate", "Vulkan GLSL 4.50", g.entry) + " / " +
                       instructions("peer_combined", "Vulkan GLSL 4.50", g.entry)
                 : "—")
        << " | " << peer_ratios(g, 0, false) << " | " << peer_ratios(g, 0, true) << " |\n";
  }
  out << "\nThe per-frame path (shaders_runtime/per_frame.glsl: the sky from a sky view, aerial perspective from "
         "a volume; irradiance has no per-frame table), per pixel as above, and its time per pixel against the "
         "direct lookup's and the peer's (separate / combined):\n\n"
         "| case group | texture fetches | transcendental calls | SPIR-V instructions after `spirv-opt -O` "
         "| GL, ratio to the direct lookup | GL, ratio to the peer | Vulkan, ratio to the direct lookup "
         "| Vulkan, ratio to the peer |\n"
         "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n";
  for (const Group& g : groups) {
    auto count_cell = [&](const Statistic Counts::*statistic) {
      std::vector<double> maxima =
          values(g, [&](const CaseResult& c) { return (c.runtimes[1].counts.*statistic).max; });
      return Range(values(g, [&](const CaseResult& c) { return (c.runtimes[1].counts.*statistic).mean; }), "%.1f") +
             " (" + Format("%.0f", *std::max_element(maxima.begin(), maxima.end())) + ")";
    };
    auto direct_ratio = [&](bool vulkan) {
      return RatioRange(values(g, [&](const CaseResult& c) {
        auto median = [&](size_t k) { return Median(vulkan ? c.runtimes[k].vulkan_seconds : c.runtimes[k].gl_seconds); };
        return median(1) / median(0);
      }));
    };
    out << "| " << g.name << " | " << count_cell(&Counts::fetches) << " | " << count_cell(&Counts::calls) << " | "
        << instructions("skybake_per_frame", "Vulkan GLSL 4.50", g.entry) << " | " << direct_ratio(false) << " | "
        << peer_ratios(g, 1, false) << " | " << direct_ratio(true) << " | " << peer_ratios(g, 1, true) << " |\n";
  }

  // What building the per-frame tables costs each frame: one direct lookup
  // per texel, at the direct lookups' time per pixel measured above (the
  // sky from 1 m, aerial perspective from 300 m).
  const double sky_view_texels = double(glsl::SKY_VIEW_WIDTH) * glsl::SKY_VIEW_HEIGHT;
  const double volume_texels = 32.0 * 32.0 * glsl::AERIAL_PERSPECTIVE_SLICES;
  out << "\nBuilding the per-frame tables each frame: " << Format("%.0f", sky_view_texels) << " sky lookups ("
      << glsl::SKY_VIEW_WIDTH << "×" << glsl::SKY_VIEW_HEIGHT << ") and " << Format("%.0f", volume_texels)
      << " aerial-perspective lookups (32×32 froxels, " << glsl::AERIAL_PERSPECTIVE_SLICES
      << " slices); at the direct lookups' median time per pixel above (sky from 1 m, aerial perspective from "
         "300 m), per frame:\n\n| sun | GL ms | Vulkan ms |\n| --- | ---: | ---: |\n";
  for (double sun : [&] {
         std::vector<double> suns;
         for (const CaseResult& c : m.cases)
           if (std::find(suns.begin(), suns.end(), c.c.sun_zenith_deg) == suns.end()) suns.push_back(c.c.sun_zenith_deg);
         return suns;
       }()) {
    double gl_ms = 0.0, vulkan_ms = 0.0;
    bool vulkan_timed = true;
    for (const CaseResult& c : m.cases) {
      if (c.c.sun_zenith_deg != sun) continue;
      const bool sky = c.c.entry == Entry::kSky && c.c.altitude_m == 1.0, aerial = c.c.entry == Entry::kAerial;
      if (!sky && !aerial) continue;
      const double texels = (sky ? sky_view_texels : volume_texels) / (double(m.size) * m.size);
      gl_ms += 1e3 * Median(c.runtimes[0].gl_seconds) * texels;
      if (c.runtimes[0].vulkan_seconds.empty()) vulkan_timed = false;
      else vulkan_ms += 1e3 * Median(c.runtimes[0].vulkan_seconds) * texels;
    }
    out << "| " << Degrees(sun) << " | " << Format("%.2f", gl_ms) << " | "
        << (vulkan_timed ? Format("%.2f", vulkan_ms) : std::string("—")) << " |\n";
  }

  out << "\nEach case (counts: mean and largest; scalar components of the transcendental calls, a vec3 `exp` "
         "being 3; times: medians in milliseconds), skybake / its per-frame path / peer separate / peer combined:\n\n"
         "| case | fetches | transcendental calls | their scalar components | GL ms | Vulkan ms |\n"
         "| --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (const CaseResult& c : m.cases) {
    auto cells = [&](auto of) {
      std::string cell;
      for (size_t r = 0; r < m.runtimes.size(); ++r) cell += (r ? " / " : "") + of(c.runtimes[r]);
      return cell;
    };
    auto statistic = [&](const Statistic Counts::*s) {
      return cells([&](const RuntimeResult& r) {
        return Format("%.1f", (r.counts.*s).mean) + " (" + Format("%.0f", (r.counts.*s).max) + ")";
      });
    };
    out << "| " << c.c.name << " | " << statistic(&Counts::fetches) << " | " << statistic(&Counts::calls) << " | "
        << statistic(&Counts::scalars) << " | "
        << cells([](const RuntimeResult& r) { return Format("%.1f", 1e3 * Median(r.gl_seconds)); }) << " | "
        << cells([](const RuntimeResult& r) {
             return r.vulkan_seconds.empty() ? std::string("—") : Format("%.1f", 1e3 * Median(r.vulkan_seconds));
           })
        << " |\n";
  }

  out << "\nCompiling for Vulkan: glslangValidator to SPIR-V (wall time, with the process start), lavapipe's "
         "pipeline creation (vkCreateShaderModule and vkCreateComputePipelines), the first dispatch after it (64 "
         "invocations), and the SPIR-V instructions as glslang writes them and after `spirv-opt -O`:\n\n"
         "| runtime | language | entry point | glslang s | pipeline creation s | first dispatch s "
         "| SPIR-V instructions | after `spirv-opt -O` |\n"
         "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: |\n";
  for (const CompiledShader& s : m.shaders) {
    out << "| " << s.runtime << " | " << s.language << " | " << EntryName(s.entry) << " | "
        << Format("%.2f", s.glslang_seconds) << " | " << Format("%.2f", s.pipeline_seconds) << " | "
        << Format("%.3f", s.first_dispatch_seconds) << " | " << s.instructions << " | "
        << (s.optimized_instructions < 0 ? "—" : std::to_string(s.optimized_instructions)) << " |\n";
  }
  out << "\nDrivers: " << m.gl_driver << " (counted and timed; the counting build also compiles and runs on "
      << m.gl_es_driver << "); " << m.vulkan_driver << ".\n";
  return out.str();
}

// ---- the command line ----

const char kUsage[] =
    "usage: skybake_runtime_cost --luts DIR [--peer DIR] [--size N] [--runs K] [--suns Z1,Z2,...] [--no-hlsl]\n"
    "                            [--vulkan-entries sky,aerial,irradiance] [--json FILE] [--markdown FILE]\n";

Options ParseOptions(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--no-hlsl") {
      o.hlsl = false;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
    const std::string value = argv[++i];
    if (arg == "--luts")
      o.luts = value;
    else if (arg == "--peer")
      o.peer = value;
    else if (arg == "--size")
      o.size = std::stoi(value);
    else if (arg == "--runs")
      o.runs = std::stoi(value);
    else if (arg == "--json")
      o.json = value;
    else if (arg == "--markdown")
      o.markdown = value;
    else if (arg == "--vulkan-entries") {
      o.vulkan_entries.clear();
      std::istringstream in(value);
      for (std::string name; std::getline(in, name, ',');) {
        const Entry* e = std::find_if(std::begin(kEntries), std::end(kEntries),
                                      [&](Entry entry) { return name == EntryName(entry); });
        if (e == std::end(kEntries))
          throw std::invalid_argument("--vulkan-entries: not sky, aerial or irradiance: " + name);
        o.vulkan_entries.push_back(*e);
      }
    } else if (arg == "--suns") {
      o.suns.clear();
      std::istringstream in(value);
      for (std::string s; std::getline(in, s, ',');) o.suns.push_back(std::stod(s));
    } else {
      throw std::invalid_argument("unknown option " + arg);
    }
  }
  if (o.luts.empty()) throw std::invalid_argument("--luts is required");
  if (o.size < 2 || o.size % 2 || o.runs < 1 || o.suns.empty())
    throw std::invalid_argument("--size must be even and at least 2, --runs at least 1, --suns not empty");
  return o;
}

int Main(int argc, char** argv) {
  Options options;
  try {
    options = ParseOptions(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n" << kUsage;
    return 1;
  }
  auto skip = [](const std::string& why) {
    std::cout << "SKIPPED: runtime cost not measured: " << why << "\n";
    return kSkipped;
  };
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) return skip("glslangValidator is not installed");
  // Mesa keeps compiled shaders on disk: without its cache on the Vulkan
  // device, whose compile times are reported, a second run times compiles,
  // not cache look-ups. The GL contexts, whose compiles are not timed, keep it.
  setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  std::string why_not;
  std::unique_ptr<VulkanCompute> vk = VulkanCompute::Create(&why_not);
  unsetenv("MESA_SHADER_CACHE_DISABLE");
  if (!vk) return skip(why_not);
  const LutSet luts = LoadLutSet(options.luts);
  std::vector<Runtime> runtimes = Runtimes(options, luts);
  std::string gl_es_driver;
  {
    std::unique_ptr<GlContext> gl_es = GlContext::Create(GlContext::Api::kGles30, &why_not);
    if (!gl_es) return skip(why_not);
    gl_es_driver = gl_es->Description();
    CheckCountingBuild(gl_es.get(), runtimes, luts);
  }
  std::unique_ptr<GlContext> gl = GlContext::Create(GlContext::Api::kDesktop33Core, &why_not);
  if (!gl) return skip(why_not);
  Measurement m = Measure(options, luts, std::move(runtimes), gl.get(), vk.get());
  m.gl_es_driver = gl_es_driver;
  const std::string markdown = Markdown(m);
  std::cout << markdown;
  if (!options.json.empty()) std::ofstream(options.json) << ToJson(m, options).dump(2) << "\n";
  if (!options.markdown.empty()) std::ofstream(options.markdown) << markdown;
  const std::vector<std::string> failures = Check(m);
  for (const std::string& f : failures) std::cerr << "FAILED: " << f << "\n";
  return failures.empty() ? 0 : 1;
}

}  // namespace
}  // namespace skybake

int main(int argc, char** argv) {
  try {
    return skybake::Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "FAILED: " << e.what() << "\n";
    return 1;
  }
}
