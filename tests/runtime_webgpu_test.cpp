// The WGSL runtime (the shipped translation, shaders_runtime/generated/) run as
// a compute shader on a real WebGPU implementation, Dawn (the npm package
// webgpu, tests/runtime_webgpu/run_wgsl.mjs), over the queries of
// runtime_gl_test.cpp, against the CPU twin at that test's tolerances.
// Dawn runs here on OpenGL ES (llvmpipe) at the compatibility feature level,
// which cannot filter float32 textures: the tables go up as rgba16float, and
// the twin reads the same half-rounded tables.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/config.h"
#include "report/quality_ladder.h"
#include "shaders_runtime/snippet.h"
#include "tests/runtime_queries.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

// The test's compute main() in WGSL, the same switch as runtime_gl_test.cpp's
// kMain. The runtime's functions.wgsl expects the engine to declare
// skybake_linear_sampler.
const char* const kWgslMain = R"(
@group(0) @binding(0) var transmittance_texture: texture_2d<f32>;
@group(0) @binding(1) var scattering_texture: texture_3d<f32>;
@group(0) @binding(2) var single_mie_scattering_texture: texture_3d<f32>;
@group(0) @binding(3) var irradiance_texture: texture_2d<f32>;
@group(0) @binding(4) var<storage, read> skybake_inputs: array<vec4<f32>>;
@group(0) @binding(5) var<storage, read_write> skybake_outputs: array<vec4<f32>>;
@group(0) @binding(6) var skybake_linear_sampler: sampler;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
  let item = id.x;
  if (item >= arrayLength(&skybake_outputs)) { return; }
  let a = skybake_inputs[4u * item];
  let camera = a.xyz;
  let view = skybake_inputs[4u * item + 1u].xyz;
  let sun = skybake_inputs[4u * item + 2u].xyz;
  let shadow_length = skybake_inputs[4u * item + 2u].w;
  let extra = skybake_inputs[4u * item + 3u].xyz;
  let what = i32(a.w);
  var t = vec3<f32>(0.0);
  var sky = vec3<f32>(0.0);
  var v = vec3<f32>(0.0);
  if (what <= 1) {
    v = GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                       camera, view, sun, &t);
    if (what == 1) { v = t; }
  } else if (what <= 3) {
    v = GetSkyRadianceToPoint(ATMOSPHERE, transmittance_texture, scattering_texture, single_mie_scattering_texture,
                              camera, extra, sun, &t);
    if (what == 3) { v = t; }
  } else if (what <= 5) {
    v = GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, camera, extra, sun, &sky);
    if (what == 5) { v = sky; }
  } else if (what == 6) {
    v = GetTransmittanceToSun(ATMOSPHERE, transmittance_texture, length(camera), dot(camera, sun) / length(camera));
  } else if (what == 7) {
    v = GetSolarRadiance(ATMOSPHERE);
  } else {
    v = GetSkyRadianceToPointWithShadow(ATMOSPHERE, transmittance_texture, scattering_texture,
                                        single_mie_scattering_texture, camera, extra, shadow_length, sun, &t);
  }
  skybake_outputs[item] = vec4<f32>(v, 1.0);
}
)";

void WriteFloats(const std::filesystem::path& file, const float* values, size_t count) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(values), static_cast<std::streamsize>(count * sizeof(float)));
}

TEST(RuntimeOnWebGpu, WgslMatchesTheCppTwin) {
  const LutSet luts =
      report::RoundToHalf(Bake(LoadAtmosphere("earth"), testing::RuntimeTestSettings(false)));
  const std::vector<testing::RuntimeQuery> queries =
      testing::MakeRuntimeQueries(luts.parameters.bottom_radius, luts.parameters.top_radius);
  ASSERT_GE(queries.size(), 1000u);

  testing::TempDir dir;
  nlohmann::json job = {{"shader", "runtime.wgsl"}, {"inputs", "inputs.f32"}, {"items", queries.size()},
                        {"output", "outputs.f32"},  {"input_binding", 4},   {"output_binding", 5},
                        {"sampler_binding", 6},     {"textures", nlohmann::json::array()}};
  testing::WriteText(dir.path() / "runtime.wgsl",
                     RuntimeSnippetSource(ShadingLanguage::kWgsl, luts.parameters, luts.atmosphere.wavelengths_nm,
                                          luts.atmosphere.name) +
                         kWgslMain);
  const glsl::Texture* tables[] = {&luts.transmittance, &luts.scattering, &luts.single_mie_scattering,
                                   &luts.irradiance};
  for (int binding = 0; binding < 4; ++binding) {
    const glsl::Texture& t = *tables[binding];
    const std::string file = "texture" + std::to_string(binding) + ".f32";
    WriteFloats(dir.path() / file, t.texels.data(), t.texels.size());
    job["textures"].push_back(
        {{"binding", binding}, {"width", t.width}, {"height", t.height}, {"depth", t.depth}, {"file", file}});
  }
  const std::vector<std::array<float, 4>> inputs = testing::RuntimeQueryInputs(queries);
  WriteFloats(dir.path() / "inputs.f32", inputs[0].data(), inputs.size() * 4);
  testing::WriteText(dir.path() / "job.json", job.dump(2));

  std::string out;
  const int status = testing::RunWgslJob(dir.path(), &out);
  if (status == 77) GTEST_SKIP() << out;
  ASSERT_EQ(status, 0) << out;

  std::ifstream in(dir.path() / "outputs.f32", std::ios::binary);
  std::vector<std::array<float, 4>> outputs(queries.size());
  in.read(reinterpret_cast<char*>(outputs.data()), static_cast<std::streamsize>(outputs.size() * sizeof(outputs[0])));
  ASSERT_TRUE(in) << "the runner wrote too few outputs";
  std::string device = out.substr(0, out.find('\n'));
  testing::ExpectMatchesTwin("WGSL on " + device, luts, queries, outputs);
}

}  // namespace
}  // namespace skybake

namespace skybake {
namespace {

// A scene's WGSL leaves out the functions of the tables the scene does
// without (WGSL has no preprocessor: the bake drops them by the marks the
// translation puts on them), and what remains compiles on Dawn with a main()
// that calls each function kept.
TEST(RuntimeWgsl, SceneLeavesOutTheFunctionsOfMissingTables) {
  const Atmosphere earth = LoadAtmosphere("earth");
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, testing::SmallBakeSettings());
  struct Entry {
    const char* function;
    const char* call;
  };
  const Entry entries[] = {
      {"fn GetSkyRadiance(", "GetSkyRadiance(ATMOSPHERE, t2, t3, t3, x, x, x, &t)"},
      {"fn GetSunAndSkyIrradiance(", "GetSunAndSkyIrradiance(ATMOSPHERE, t2, t2, x, x, x, &t)"},
      {"fn GetSkyRadianceToPoint(", "GetSkyRadianceToPoint(ATMOSPHERE, t2, t3, t3, x, x, x, &t)"}};
  for (const SnippetParts parts : {SnippetParts{true, true, true}, SnippetParts{true, false, false},
                                   SnippetParts{false, true, false}, SnippetParts{true, false, true}}) {
    SCOPED_TRACE(std::string("scattering ") + std::to_string(parts.scattering) + " irradiance " +
                 std::to_string(parts.irradiance) + " aerial " + std::to_string(parts.aerial_perspective));
    const std::string wgsl = RuntimeSnippetSource(ShadingLanguage::kWgsl, p, earth.wavelengths_nm, earth.name, parts);
    const bool has[] = {parts.scattering, parts.irradiance, parts.aerial_perspective};
    std::string calls;
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(wgsl.find(entries[k].function) != std::string::npos, has[k]) << entries[k].function;
      if (has[k]) calls += "  v += " + std::string(entries[k].call) + ";\n";
    }
    EXPECT_NE(wgsl.find("fn GetTransmittanceToSun("), std::string::npos);
    std::string out;
    const int status = testing::CompileWgsl(
        wgsl + "@group(0) @binding(0) var t2: texture_2d<f32>;\n"
               "@group(0) @binding(1) var t3: texture_3d<f32>;\n"
               "@group(0) @binding(2) var skybake_linear_sampler: sampler;\n"
               "@group(0) @binding(3) var<storage, read_write> o: array<vec4<f32>>;\n"
               "@compute @workgroup_size(1)\nfn main() {\n  let x = vec3<f32>(0.0, 0.0, 6.4e6);\n"
               "  var t = vec3<f32>(0.0);\n"
               "  var v = GetTransmittanceToSun(ATMOSPHERE, t2, 6.4e6, 0.5);\n" +
            calls + "  o[0] = vec4<f32>(v + t, 1.0);\n}\n",
        &out);
    if (status == 77) GTEST_SKIP() << out;
    EXPECT_EQ(status, 0) << out;
  }
}

}  // namespace
}  // namespace skybake
