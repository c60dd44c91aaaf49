// The code in shaders_runtime/README.md compiles as written: the minimal
// OpenGL fragment shader and the engine quick starts (HLSL for Unity, WGSL,
// Vulkan GLSL), each with the runtime files of a bake and a main() that calls
// what the block defines or declares. The HLSL and GLSL go through glslang,
// the WGSL through Dawn (a shader module and a compute pipeline).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "bake/config.h"
#include "examples/engine/vulkan_compute.h"
#include "shaders_runtime/snippet.h"
#include "tests/runtime_queries.h"
#include "tests/test_atmospheres.h"
#include "tests/test_util.h"

namespace skybake {
namespace {

// The fenced code blocks of `language` in the README's section `heading`.
std::vector<std::string> CodeBlocks(const std::string& heading, const std::string& language) {
  const std::string text =
      testing::ReadText(std::filesystem::path(SKYBAKE_SOURCE_DIR) / "shaders_runtime" / "README.md");
  const size_t start = text.find("\n## " + heading + "\n");
  if (start == std::string::npos) return {};
  const size_t end = text.find("\n## ", start + 1);
  const std::string section = text.substr(start, end - start);
  std::vector<std::string> blocks;
  const std::string fence = "```" + language + "\n";
  for (size_t at = section.find(fence); at != std::string::npos; at = section.find(fence, at + 1)) {
    const size_t body = at + fence.size();
    blocks.push_back(section.substr(body, section.find("```", body) - body));
  }
  return blocks;
}

std::string Runtime(ShadingLanguage language) {
  const Atmosphere earth = LoadAtmosphere("earth");
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, testing::SmallBakeSettings());
  return RuntimeSnippetSource(language, p, earth.wavelengths_nm, earth.name);
}

class QuickStarts : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
  }
};

TEST_F(QuickStarts, MinimalOpenGlFragmentShaderCompiles) {
  const std::vector<std::string> blocks = CodeBlocks("A minimal fragment shader", "glsl");
  ASSERT_EQ(blocks.size(), 1u);
  // The block starts with its #version line; the runtime goes after it.
  const std::string& block = blocks[0];
  const size_t version_end = block.find('\n') + 1;
  testing::TempDir dir;
  testing::WriteText(dir.path() / "sky.frag", block.substr(0, version_end) + Runtime(ShadingLanguage::kGlsl) +
                                                  block.substr(version_end));
  std::string log;
  EXPECT_EQ(testing::RunCommand(testing::ShellQuote(SKYBAKE_GLSLANG_VALIDATOR) + " " +
                                    testing::ShellQuote(dir.path() / "sky.frag"),
                                dir, &log),
            0)
      << log;
}

TEST_F(QuickStarts, UnityHlslCompiles) {
  const std::vector<std::string> blocks = CodeBlocks("Engine quick starts", "hlsl");
  ASSERT_EQ(blocks.size(), 1u);
  // The block #includes the three files; here they are pasted in their place.
  std::string block = blocks[0];
  for (const char* file : {"definitions.hlsl", "atmosphere_constants.hlsl", "functions.hlsl"}) {
    const std::string include = std::string("#include \"") + file + "\"\n";
    ASSERT_NE(block.find(include), std::string::npos) << file;
    block.erase(block.find(include), include.size());
  }
  const std::string source = Runtime(ShadingLanguage::kHlsl) + block +
                             "RWStructuredBuffer<float4> o;\n[numthreads(1, 1, 1)] void main() {\n"
                             "  float3 t;\n  o[0] = float4(SkyRadiance(float3(0.0, 0.0, 6.4e6), float3(0.0, 0.0, 1.0),"
                             " float3(0.0, 0.0, 1.0), t) + t, 1.0);\n}\n";
  std::string log;
  EXPECT_FALSE(CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, source, true, &log).empty()) << log;
}

TEST_F(QuickStarts, VulkanGlslCompiles) {
  const std::vector<std::string> blocks = CodeBlocks("Engine quick starts", "glsl");
  ASSERT_EQ(blocks.size(), 1u);
  const std::string source = "#version 450\n" + Runtime(ShadingLanguage::kGlsl) + blocks[0] +
                             "layout(std430, set = 0, binding = 5) buffer Out { vec4 o[]; };\n"
                             "layout(local_size_x = 1) in;\nvoid main() {\n  vec3 t, sky;\n"
                             "  vec3 camera = vec3(0.0, 0.0, 6.4e6), up = vec3(0.0, 0.0, 1.0);\n"
                             "  o[0] = vec4(GetSkyRadiance(ATMOSPHERE, transmittance_texture, scattering_texture,\n"
                             "      single_mie_scattering_texture, camera, up, up, t) +\n"
                             "    GetSunAndSkyIrradiance(ATMOSPHERE, transmittance_texture, irradiance_texture, camera,"
                             " up, up, sky) + sky, 1.0);\n}\n";
  std::string log;
  EXPECT_FALSE(CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, source, false, &log).empty()) << log;
}

TEST(QuickStartsOnWebGpu, WgslCompilesIntoAComputePipeline) {
  const std::vector<std::string> blocks = CodeBlocks("Engine quick starts", "wgsl");
  ASSERT_EQ(blocks.size(), 1u);
  std::string out;
  const int status = testing::CompileWgsl(
      Runtime(ShadingLanguage::kWgsl) + blocks[0] +
          "@group(0) @binding(5) var<storage, read_write> o: array<vec4<f32>>;\n"
          "@compute @workgroup_size(1)\nfn main() {\n"
          "  o[0] = vec4<f32>(Sky(vec3<f32>(0.0, 0.0, 6.4e6), vec3<f32>(0.0, 0.0, 1.0),"
          " vec3<f32>(0.0, 0.0, 1.0)), 1.0);\n}\n",
      &out);
  if (status == 77) GTEST_SKIP() << out;
  EXPECT_EQ(status, 0) << out;
}

}  // namespace
}  // namespace skybake
