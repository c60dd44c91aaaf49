// A headless Vulkan device for tests that run compute shaders on a real
// driver (Mesa's lavapipe here: Vulkan on the CPU) and read the results back.
//
// Typical use:
//   std::string why;
//   auto vk = skybake::testing::VulkanCompute::Create(&why);
//   if (!vk) GTEST_SKIP() << why;
//   vk->SetTexture(0, width, height, 1, rgba);
//   auto out = vk->Run(spirv, VulkanCompute::Samplers::kCombined, inputs, 4);
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace skybake::testing {

using Vec4 = std::array<float, 4>;

class VulkanCompute {
 public:
  // The tables' bindings are 0 to kTextureCount - 1.
  static constexpr int kTextureCount = 4;
  static constexpr int kInputBinding = 4;    // readonly buffer of vec4: the items' inputs
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

  // An RGBA32F texture (depth 1: 2D, else 3D), x fastest, at `binding`.
  void SetTexture(int binding, int width, int height, int depth, const std::vector<float>& rgba);

  // Runs the compute shader `spirv` (entry point "main", 64 invocations per
  // workgroup in x) over inputs.size() / inputs_per_item items: invocation i
  // reads inputs i*inputs_per_item ... and writes output i; invocations past
  // the last item must write nothing (the output buffer's length is the item
  // count). Throws std::runtime_error on any Vulkan error.
  std::vector<Vec4> Run(const std::vector<std::uint32_t>& spirv, Samplers samplers, const std::vector<Vec4>& inputs,
                        int inputs_per_item);

 private:
  struct Impl;
  VulkanCompute();
  std::unique_ptr<Impl> impl_;
};

}  // namespace skybake::testing
