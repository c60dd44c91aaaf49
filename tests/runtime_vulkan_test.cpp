// The runtime in Vulkan GLSL 4.50 and in HLSL, compiled by glslang to SPIR-V
// and run as compute shaders on a real Vulkan driver (Mesa's lavapipe here),
// gives the CPU twin's numbers on the queries of runtime_gl_test.cpp within
// that test's tolerances (tests/runtime_queries.h). The HLSL is the shipped
// translation (shaders_runtime/generated/, from the GLSL by spirv-cross), read
// by glslang's HLSL front end, so this also checks that the translation keeps
// every function's meaning.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <memory>
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

// The test's compute main() in Vulkan GLSL: explicit bindings as an engine
// declares them, a query per invocation (EvaluateQuery, tests/runtime_queries.h).
const std::string kVulkanGlslMain = std::string(VulkanCompute::kGlslTables) + R"(
layout(std430, set = 0, binding = 4) readonly buffer Inputs { vec4 skybake_inputs[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Outputs { vec4 skybake_outputs[]; };
layout(local_size_x = 64) in;
)" + testing::kGlslEvaluateQuery + R"(
void main() {
  uint item = gl_GlobalInvocationID.x;
  if (item >= uint(skybake_outputs.length())) return;
  skybake_outputs[item] = vec4(EvaluateQuery(skybake_inputs[4u * item], skybake_inputs[4u * item + 1u],
                                             skybake_inputs[4u * item + 2u], skybake_inputs[4u * item + 3u]), 1.0);
}
)";

// The same query in HLSL: each texture with the sampler (the translation
// takes a Texture and a SamplerState for each table).
const char* const kHlslMain = R"(
[[vk::binding(0)]] Texture2D<float4> transmittance_texture;
[[vk::binding(1)]] Texture3D<float4> scattering_texture;
[[vk::binding(2)]] Texture3D<float4> single_mie_scattering_texture;
[[vk::binding(3)]] Texture2D<float4> irradiance_texture;
[[vk::binding(4)]] StructuredBuffer<float4> skybake_inputs;
[[vk::binding(5)]] RWStructuredBuffer<float4> skybake_outputs;
[[vk::binding(6)]] SamplerState linear_sampler;
[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
  uint count, stride;
  skybake_outputs.GetDimensions(count, stride);
  uint item = id.x;
  if (item >= count) return;
  float4 a = skybake_inputs[4 * item];
  float3 camera = a.xyz, view = skybake_inputs[4 * item + 1].xyz, sun = skybake_inputs[4 * item + 2].xyz;
  float3 extra = skybake_inputs[4 * item + 3].xyz;
  float shadow_length = skybake_inputs[4 * item + 2].w;
  int what = int(a.w);
  AtmosphereParameters atmosphere = ATMOSPHERE;
  float3 t, sky, v = float3(0.0, 0.0, 0.0);
  if (what <= 1) {
    v = GetSkyRadiance(atmosphere, transmittance_texture, linear_sampler, scattering_texture, linear_sampler,
                       single_mie_scattering_texture, linear_sampler, camera, view, sun, t);
    if (what == 1) v = t;
  } else if (what <= 3) {
    v = GetSkyRadianceToPoint(atmosphere, transmittance_texture, linear_sampler, scattering_texture, linear_sampler,
                              single_mie_scattering_texture, linear_sampler, camera, extra, sun, t);
    if (what == 3) v = t;
  } else if (what <= 5) {
    v = GetSunAndSkyIrradiance(atmosphere, transmittance_texture, linear_sampler, irradiance_texture, linear_sampler,
                               camera, extra, sun, sky);
    if (what == 5) v = sky;
  } else if (what == 6) {
    v = GetTransmittanceToSun(atmosphere, transmittance_texture, linear_sampler, length(camera),
                              dot(camera, sun) / length(camera));
  } else if (what == 7) {
    v = GetSolarRadiance(atmosphere);
  } else {
    v = GetSkyRadianceToPointWithShadow(atmosphere, transmittance_texture, linear_sampler, scattering_texture,
                                        linear_sampler, single_mie_scattering_texture, linear_sampler, camera,
                                        extra, shadow_length, sun, t);
  }
  skybake_outputs[item] = float4(v, 1.0);
}
)";

std::string RuntimeSource(ShadingLanguage language, const LutSet& luts, const SnippetParts& parts = {}) {
  return RuntimeSnippetSource(language, luts.parameters, luts.atmosphere.wavelengths_nm, luts.atmosphere.name, parts);
}

class RuntimeOnVulkan : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { luts_ = new LutSet(Bake(LoadAtmosphere("earth"), testing::RuntimeTestSettings(false))); }
  static void TearDownTestSuite() {
    delete luts_;
    luts_ = nullptr;
  }

  // Compiles `source`, runs it over the queries on lavapipe and compares with the twin.
  void ExpectMatchesTwin(const std::string& source, bool hlsl) {
    if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
    std::string why_not;
    std::unique_ptr<VulkanCompute> vk = VulkanCompute::Create(&why_not);
    if (!vk) GTEST_SKIP() << why_not;
    const LutSet& luts = *luts_;
    const glsl::Texture* tables[] = {&luts.transmittance, &luts.scattering, &luts.single_mie_scattering,
                                     &luts.irradiance};
    for (int binding = 0; binding < VulkanCompute::kTextureCount; ++binding) {
      const glsl::Texture& t = *tables[binding];
      vk->SetTexture(binding, t.width, t.height, t.depth, t.texels.data(), t.texels.size());
    }
    std::string log;
    const std::vector<std::uint32_t> spirv = CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, source, hlsl, &log);
    ASSERT_FALSE(spirv.empty()) << log;
    const std::vector<testing::RuntimeQuery> queries =
        testing::MakeRuntimeQueries(luts.parameters.bottom_radius, luts.parameters.top_radius);
    ASSERT_GE(queries.size(), 1000u);
    const auto samplers = hlsl ? VulkanCompute::Samplers::kSeparate : VulkanCompute::Samplers::kCombined;
    testing::ExpectMatchesTwin(std::string(hlsl ? "HLSL" : "Vulkan GLSL 4.50") + " on " + vk->Description(), luts,
                               queries, vk->Run(spirv, samplers, testing::RuntimeQueryInputs(queries), queries.size()));
  }

  static LutSet* luts_;
};

LutSet* RuntimeOnVulkan::luts_ = nullptr;

TEST_F(RuntimeOnVulkan, VulkanGlslMatchesTheCppTwin) {
  ExpectMatchesTwin("#version 450\n" + RuntimeSource(ShadingLanguage::kGlsl, *luts_) + kVulkanGlslMain, false);
}

TEST_F(RuntimeOnVulkan, HlslMatchesTheCppTwin) {
  ExpectMatchesTwin(RuntimeSource(ShadingLanguage::kHlsl, *luts_) + kHlslMain, true);
}

// The HLSL keeps the GLSL's scene switches: with a table left out, its
// functions are gone (a shader calling them fails to compile) and the rest
// compiles.
TEST(RuntimeHlsl, SceneSwitchesLeaveOutTheFunctionsOfMissingTables) {
  if (std::string(SKYBAKE_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "glslangValidator is not installed";
  const Atmosphere earth = LoadAtmosphere("earth");
  const glsl::AtmosphereParameters p = MakeAtmosphereParameters(earth, testing::SmallBakeSettings());
  const char* const calls[] = {
      "GetSkyRadiance(a, transmittance_texture, s, scattering_texture, s, scattering_texture, s, x, x, x, t)",
      "GetSunAndSkyIrradiance(a, transmittance_texture, s, irradiance_texture, s, x, x, x, t)",
      "GetSkyRadianceToPoint(a, transmittance_texture, s, scattering_texture, s, scattering_texture, s, x, x, x, t)"};
  auto shader = [&](const SnippetParts& parts, const char* call) {
    return RuntimeSnippetSource(ShadingLanguage::kHlsl, p, earth.wavelengths_nm, earth.name, parts) +
           "Texture2D<float4> transmittance_texture; Texture3D<float4> scattering_texture;\n"
           "Texture2D<float4> irradiance_texture; SamplerState s; RWStructuredBuffer<float4> o;\n"
           "[numthreads(1, 1, 1)] void main() {\n  AtmosphereParameters a = ATMOSPHERE;\n"
           "  float3 x = float3(0.0, 0.0, 6.4e6), t;\n  o[0] = float4(" +
           call + " + GetTransmittanceToSun(a, transmittance_texture, s, 6.4e6, 0.5), 1.0);\n}\n";
  };
  for (const SnippetParts parts : {SnippetParts{true, true, true}, SnippetParts{true, false, false},
                                   SnippetParts{false, true, false}, SnippetParts{true, false, true}}) {
    const bool has[] = {parts.scattering, parts.irradiance, parts.aerial_perspective};
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE(std::string("scattering ") + std::to_string(parts.scattering) + " irradiance " +
                   std::to_string(parts.irradiance) + " aerial " + std::to_string(parts.aerial_perspective) +
                   ", calling " + calls[k]);
      std::string log;
      EXPECT_EQ(!CompileComputeShader(SKYBAKE_GLSLANG_VALIDATOR, shader(parts, calls[k]), true, &log).empty(), has[k])
          << log;
    }
  }
}

}  // namespace
}  // namespace skybake
