// A headless Vulkan device that runs one compute shader over a number of
// items with the runtime's four tables bound, and reads one vec4 per item
// back: what the Vulkan engine example (vulkan_example.cpp) renders with, and
// what the runtime tests run the Vulkan GLSL and the HLSL on. No window
// system or GPU is needed: Mesa's lavapipe runs Vulkan on the CPU.
//
// Typical use:
//   std::string why;
//   auto vk = skybake::VulkanCompute::Create(&why);
//   if (!vk) ... why says what is missing
//   vk->SetTexture(0, width, height, 1, rgba.data(), rgba.size());
//   auto out = vk->Run(spirv, VulkanCompute::Samplers::kCombined, inputs, items);
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace skybake {

class VulkanCompute {
 public:
  // The tables' bindings are 0 to kTextureCount - 1.
  static constexpr int kTextureCount = 4;
  // The tables at those bindings, declared in Vulkan GLSL as a compute
  // shader around the runtime declares them (Samplers::kCombined).
  static constexpr const char kGlslTables[] =
      "layout(set = 0, binding = 0) uniform sampler2D transmittance_texture;\n"
      "layout(set = 0, binding = 1) uniform sampler3D scattering_texture;\n"
      "layout(set = 0, binding = 2) uniform sampler3D single_mie_scattering_texture;\n"
      "layout(set = 0, binding = 3) uniform sampler2D irradiance_texture;\n";
  static constexpr int kInputBinding = 4;    // readonly buffer of vec4: the shader's inputs
  static constexpr int kOutputBinding = 5;   // buffer of vec4: one per item
  static constexpr int kSamplerBinding = 6;  // with Samplers::kSeparate

  // How the shader declares the textures: combined image samplers (GLSL
  // sampler2D / sampler3D), or sampled images (HLSL Texture2D, WGSL
  // texture_2d) and one sampler at kSamplerBinding. Either way the sampler
  // filters linearly and clamps to the edge, as the runtime requires.
  enum class Samplers { kCombined, kSeparate };

  // Empty, with `why_not` set to a one-line reason, if there is no Vulkan
  // loader, device or linear filtering of RGBA32F.
  static std::unique_ptr<VulkanCompute> Create(std::string* why_not);
  ~VulkanCompute();
  VulkanCompute(const VulkanCompute&) = delete;
  VulkanCompute& operator=(const VulkanCompute&) = delete;

  // The device and driver, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), Vulkan 1.3.230, Mesa 22.3.6".
  std::string Description() const;

  // An RGBA32F texture (depth 1: 2D, else 3D), x fastest, at `binding`:
  // the `values` floats from `rgba`, width * height * depth * 4 of them.
  void SetTexture(int binding, int width, int height, int depth, const float* rgba, std::size_t values);

  // Runs the compute shader `spirv` (entry point "main", 64 invocations per
  // workgroup in x) over `items` items: invocation i writes output i,
  // reading what it needs of `inputs`; invocations past the last item must
  // write nothing (the output buffer's length is the item count). Throws
  // std::runtime_error on any Vulkan error.
  std::vector<std::array<float, 4>> Run(const std::vector<std::uint32_t>& spirv, Samplers samplers,
                                        const std::vector<std::array<float, 4>>& inputs, std::size_t items);

  // For timing a shader (tests/runtime_cost.cpp): pipelines created once and
  // dispatched any number of times. CreatePipeline makes the compute
  // pipeline of `spirv` (as Run does), kept until the device goes, and
  // returns its index, with the wall seconds of vkCreateShaderModule and
  // vkCreateComputePipelines in `seconds`.
  int CreatePipeline(const std::vector<std::uint32_t>& spirv, Samplers samplers, double* seconds);
  // Runs pipeline `pipeline` as Run runs its shader and returns the wall
  // seconds from vkQueueSubmit until vkQueueWaitIdle returns (the buffers
  // and descriptors are made before and not counted); the outputs go to
  // `outputs` if not null. A driver that finishes compiling at the first
  // dispatch counts that in the first call: dispatch once untimed first.
  double TimeDispatch(int pipeline, const std::vector<std::array<float, 4>>& inputs, std::size_t items,
                      std::vector<std::array<float, 4>>* outputs);

 private:
  struct Impl;
  VulkanCompute();
  std::unique_ptr<Impl> impl_;
};

// SPIR-V of a compute shader (entry point "main") compiled by the
// glslangValidator at `compiler` for Vulkan 1.1: GLSL, or HLSL with `hlsl`.
// Empty if it does not compile, with the compiler's output in `log`.
std::vector<std::uint32_t> CompileComputeShader(const std::string& compiler, const std::string& source, bool hlsl,
                                                std::string* log);

}  // namespace skybake
