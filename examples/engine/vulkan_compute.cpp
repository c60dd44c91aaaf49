#include "examples/engine/vulkan_compute.h"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>

#if SKYBAKE_HAVE_VULKAN
#include <vulkan/vulkan.h>
#endif

namespace skybake {

#if SKYBAKE_HAVE_VULKAN

namespace {

void Check(VkResult result, const char* what) {
  if (result != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(result));
}

}  // namespace

struct VulkanCompute::Impl {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
  std::string description;

  // A buffer or image with its memory.
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
  };
  struct Texture {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
  };
  Texture textures[kTextureCount];

  // The pipeline of the last Run, kept for the next one with the same shader
  // (compiling it is most of a run's time on lavapipe).
  struct Pipeline {
    std::vector<std::uint32_t> spirv;
    Samplers samplers = Samplers::kCombined;
    std::vector<VkDescriptorSetLayoutBinding> bindings;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkShaderModule module = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
  } cached;
  std::vector<Pipeline> kept;  // from CreatePipeline, by index

  void DestroyPipeline(Pipeline* p) {
    if (p->pipeline) vkDestroyPipeline(device, p->pipeline, nullptr);
    if (p->module) vkDestroyShaderModule(device, p->module, nullptr);
    if (p->layout) vkDestroyPipelineLayout(device, p->layout, nullptr);
    if (p->set_layout) vkDestroyDescriptorSetLayout(device, p->set_layout, nullptr);
    *p = Pipeline{};
  }

  // The pipeline for `spirv` and `samplers`: the cached one, or a new one.
  const Pipeline& PipelineFor(const std::vector<std::uint32_t>& spirv, Samplers samplers) {
    if (cached.pipeline && cached.spirv == spirv && cached.samplers == samplers) return cached;
    DestroyPipeline(&cached);
    cached = MakePipeline(spirv, samplers);
    return cached;
  }

  // A new pipeline for `spirv` and `samplers`.
  Pipeline MakePipeline(const std::vector<std::uint32_t>& spirv, Samplers samplers) {
    Pipeline p;
    p.spirv = spirv;
    p.samplers = samplers;
    const bool combined = samplers == Samplers::kCombined;
    for (int i = 0; i < kTextureCount; ++i) {
      p.bindings.push_back({uint32_t(i),
                            combined ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, 1,
                            VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    }
    for (int b : {kInputBinding, kOutputBinding}) {
      p.bindings.push_back({uint32_t(b), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    }
    if (!combined) {
      p.bindings.push_back(
          {uint32_t(kSamplerBinding), VK_DESCRIPTOR_TYPE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
    }
    try {
      VkDescriptorSetLayoutCreateInfo set_layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
      set_layout_info.bindingCount = uint32_t(p.bindings.size());
      set_layout_info.pBindings = p.bindings.data();
      Check(vkCreateDescriptorSetLayout(device, &set_layout_info, nullptr, &p.set_layout),
            "vkCreateDescriptorSetLayout");
      VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
      layout_info.setLayoutCount = 1;
      layout_info.pSetLayouts = &p.set_layout;
      Check(vkCreatePipelineLayout(device, &layout_info, nullptr, &p.layout), "vkCreatePipelineLayout");
      VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      module_info.codeSize = spirv.size() * sizeof(std::uint32_t);
      module_info.pCode = spirv.data();
      Check(vkCreateShaderModule(device, &module_info, nullptr, &p.module), "vkCreateShaderModule");
      VkComputePipelineCreateInfo pipeline_info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
      pipeline_info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      pipeline_info.stage.module = p.module;
      pipeline_info.stage.pName = "main";
      pipeline_info.layout = p.layout;
      Check(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &p.pipeline),
            "vkCreateComputePipelines");
    } catch (...) {
      DestroyPipeline(&p);
      throw;
    }
    return p;
  }

  ~Impl() {
    if (device) {
      vkDeviceWaitIdle(device);
      DestroyPipeline(&cached);
      for (Pipeline& p : kept) DestroyPipeline(&p);
      for (Texture& t : textures) DestroyTexture(&t);
      if (sampler) vkDestroySampler(device, sampler, nullptr);
      if (pool) vkDestroyCommandPool(device, pool, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }

  void DestroyTexture(Texture* t) {
    if (t->view) vkDestroyImageView(device, t->view, nullptr);
    if (t->image) vkDestroyImage(device, t->image, nullptr);
    if (t->memory) vkFreeMemory(device, t->memory, nullptr);
    *t = Texture{};
  }

  void DestroyBuffer(Buffer* b) {
    if (b->buffer) vkDestroyBuffer(device, b->buffer, nullptr);
    if (b->memory) vkFreeMemory(device, b->memory, nullptr);
    *b = Buffer{};
  }

  uint32_t MemoryType(uint32_t allowed, VkMemoryPropertyFlags wanted) const {
    VkPhysicalDeviceMemoryProperties properties;
    vkGetPhysicalDeviceMemoryProperties(physical, &properties);
    for (uint32_t i = 0; i < properties.memoryTypeCount; ++i) {
      if ((allowed & (1u << i)) && (properties.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    }
    throw std::runtime_error("no Vulkan memory type with the properties needed");
  }

  VkDeviceMemory Allocate(VkMemoryRequirements requirements, VkMemoryPropertyFlags wanted) {
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = requirements.size;
    info.memoryTypeIndex = MemoryType(requirements.memoryTypeBits, wanted);
    VkDeviceMemory memory;
    Check(vkAllocateMemory(device, &info, nullptr, &memory), "vkAllocateMemory");
    return memory;
  }

  // A host-visible buffer holding `bytes` (or `size` zero bytes).
  Buffer MakeBuffer(VkBufferUsageFlags usage, VkDeviceSize size, const void* bytes) {
    Buffer b;
    b.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    Check(vkCreateBuffer(device, &info, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, b.buffer, &requirements);
    b.memory = Allocate(requirements, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    Check(vkBindBufferMemory(device, b.buffer, b.memory, 0), "vkBindBufferMemory");
    void* mapped;
    Check(vkMapMemory(device, b.memory, 0, size, 0, &mapped), "vkMapMemory");
    if (bytes) std::memcpy(mapped, bytes, size);
    else std::memset(mapped, 0, size);
    vkUnmapMemory(device, b.memory);
    return b;
  }

  // Records commands with `record`, submits them and waits; returns the wall
  // seconds from the submit until the queue is idle.
  template <typename Record>
  double Submit(Record record) {
    VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocate.commandPool = pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    VkCommandBuffer commands;
    Check(vkAllocateCommandBuffers(device, &allocate, &commands), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    Check(vkBeginCommandBuffer(commands, &begin), "vkBeginCommandBuffer");
    record(commands);
    Check(vkEndCommandBuffer(commands), "vkEndCommandBuffer");
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    const auto start = std::chrono::steady_clock::now();
    Check(vkQueueSubmit(queue, 1, &submit, VK_NULL_HANDLE), "vkQueueSubmit");
    Check(vkQueueWaitIdle(queue), "vkQueueWaitIdle");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    vkFreeCommandBuffers(device, pool, 1, &commands);
    return seconds;
  }

  // Runs pipeline `p` over `items` items (VulkanCompute::Run); returns the
  // dispatch's seconds (Submit).
  double Dispatch(const Pipeline& p, const std::vector<std::array<float, 4>>& inputs, std::size_t items,
                  std::vector<std::array<float, 4>>* outputs);
};

std::unique_ptr<VulkanCompute> VulkanCompute::Create(std::string* why_not) {
  std::unique_ptr<VulkanCompute> vk(new VulkanCompute());
  Impl& d = *vk->impl_;
  VkApplicationInfo application{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  application.pApplicationName = "skybake_tests";
  application.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  instance_info.pApplicationInfo = &application;
  if (vkCreateInstance(&instance_info, nullptr, &d.instance) != VK_SUCCESS) {
    *why_not = "no Vulkan driver (vkCreateInstance failed; install mesa-vulkan-drivers for lavapipe)";
    return nullptr;
  }
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(d.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(d.instance, &count, devices.data());
  for (VkPhysicalDevice candidate : devices) {
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, nullptr);
    std::vector<VkQueueFamilyProperties> properties(families);
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, properties.data());
    for (uint32_t i = 0; i < families && !d.physical; ++i) {
      if (properties[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
        d.physical = candidate;
        d.queue_family = i;
      }
    }
    if (d.physical) break;
  }
  if (!d.physical) {
    *why_not = "no Vulkan device with a compute queue";
    return nullptr;
  }
  VkFormatProperties format;
  vkGetPhysicalDeviceFormatProperties(d.physical, VK_FORMAT_R32G32B32A32_SFLOAT, &format);
  if (!(format.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT)) {
    *why_not = "the Vulkan device cannot filter RGBA32F textures linearly";
    return nullptr;
  }
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(d.physical, &properties);
  d.description = std::string(properties.deviceName) + ", Vulkan " + std::to_string(VK_VERSION_MAJOR(properties.apiVersion)) +
                  "." + std::to_string(VK_VERSION_MINOR(properties.apiVersion)) + "." +
                  std::to_string(VK_VERSION_PATCH(properties.apiVersion));

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = d.queue_family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  if (vkCreateDevice(d.physical, &device_info, nullptr, &d.device) != VK_SUCCESS) {
    *why_not = "vkCreateDevice failed";
    return nullptr;
  }
  vkGetDeviceQueue(d.device, d.queue_family, 0, &d.queue);
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.queueFamilyIndex = d.queue_family;
  Check(vkCreateCommandPool(d.device, &pool_info, nullptr, &d.pool), "vkCreateCommandPool");
  // GL_LINEAR with GL_CLAMP_TO_EDGE and no mipmaps, as the runtime's README asks.
  VkSamplerCreateInfo sampler_info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler_info.magFilter = sampler_info.minFilter = VK_FILTER_LINEAR;
  sampler_info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler_info.addressModeU = sampler_info.addressModeV = sampler_info.addressModeW =
      VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sampler_info.maxLod = 0.0f;
  Check(vkCreateSampler(d.device, &sampler_info, nullptr, &d.sampler), "vkCreateSampler");
  return vk;
}

void VulkanCompute::SetTexture(int binding, int width, int height, int depth, const float* rgba, std::size_t values) {
  Impl& d = *impl_;
  if (binding < 0 || binding >= kTextureCount) throw std::runtime_error("texture binding out of range");
  if (values != std::size_t(width) * height * depth * 4) throw std::runtime_error("texture size mismatch");
  Impl::Texture& t = d.textures[binding];
  d.DestroyTexture(&t);
  const bool is_3d = depth > 1;
  VkImageCreateInfo image_info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  image_info.imageType = is_3d ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
  image_info.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  image_info.extent = {uint32_t(width), uint32_t(height), uint32_t(depth)};
  image_info.mipLevels = 1;
  image_info.arrayLayers = 1;
  image_info.samples = VK_SAMPLE_COUNT_1_BIT;
  image_info.tiling = VK_IMAGE_TILING_OPTIMAL;
  image_info.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  image_info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  Check(vkCreateImage(d.device, &image_info, nullptr, &t.image), "vkCreateImage");
  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(d.device, t.image, &requirements);
  t.memory = d.Allocate(requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  Check(vkBindImageMemory(d.device, t.image, t.memory, 0), "vkBindImageMemory");

  Impl::Buffer staging = d.MakeBuffer(VK_BUFFER_USAGE_TRANSFER_SRC_BIT, values * sizeof(float), rgba);
  d.Submit([&](VkCommandBuffer commands) {
    VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = t.image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                         0, nullptr, 1, &barrier);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = image_info.extent;
    vkCmdCopyBufferToImage(commands, staging.buffer, t.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &barrier);
  });
  d.DestroyBuffer(&staging);

  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = t.image;
  view_info.viewType = is_3d ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = image_info.format;
  view_info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  Check(vkCreateImageView(d.device, &view_info, nullptr, &t.view), "vkCreateImageView");
}

std::vector<std::array<float, 4>> VulkanCompute::Run(const std::vector<std::uint32_t>& spirv, Samplers samplers,
                                                    const std::vector<std::array<float, 4>>& inputs,
                                                    std::size_t items) {
  Impl& d = *impl_;
  for (const Impl::Texture& t : d.textures) {
    if (!t.view) throw std::runtime_error("every texture binding needs a texture before Run");
  }
  if (items == 0) return {};
  if (inputs.empty()) throw std::runtime_error("a compute run needs inputs");
  std::vector<std::array<float, 4>> outputs;
  d.Dispatch(d.PipelineFor(spirv, samplers), inputs, items, &outputs);
  return outputs;
}

int VulkanCompute::CreatePipeline(const std::vector<std::uint32_t>& spirv, Samplers samplers, double* seconds) {
  Impl& d = *impl_;
  const auto start = std::chrono::steady_clock::now();
  d.kept.push_back(d.MakePipeline(spirv, samplers));
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return int(d.kept.size()) - 1;
}

double VulkanCompute::TimeDispatch(int pipeline, const std::vector<std::array<float, 4>>& inputs, std::size_t items,
                                   std::vector<std::array<float, 4>>* outputs) {
  Impl& d = *impl_;
  if (pipeline < 0 || pipeline >= int(d.kept.size())) throw std::runtime_error("no such pipeline");
  for (const Impl::Texture& t : d.textures) {
    if (!t.view) throw std::runtime_error("every texture binding needs a texture before a dispatch");
  }
  if (items == 0 || inputs.empty()) throw std::runtime_error("a timed dispatch needs items and inputs");
  return d.Dispatch(d.kept[pipeline], inputs, items, outputs);
}

double VulkanCompute::Impl::Dispatch(const Pipeline& p, const std::vector<std::array<float, 4>>& inputs,
                                     std::size_t items, std::vector<std::array<float, 4>>* outputs) {
  Impl& d = *this;
  const bool combined = p.samplers == Samplers::kCombined;

  // Everything created here is destroyed at the end, also on an error.
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  Buffer input_buffer, output_buffer;
  auto release = [&] {
    if (descriptor_pool) vkDestroyDescriptorPool(d.device, descriptor_pool, nullptr);
    d.DestroyBuffer(&input_buffer);
    d.DestroyBuffer(&output_buffer);
  };
  try {
    input_buffer = d.MakeBuffer(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, inputs.size() * sizeof(inputs[0]), inputs.data());
    output_buffer = d.MakeBuffer(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, items * sizeof(inputs[0]), nullptr);

    std::vector<VkDescriptorPoolSize> sizes;  // one descriptor per binding of the pipeline's layout
    for (const VkDescriptorSetLayoutBinding& b : p.bindings) sizes.push_back({b.descriptorType, 1});
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = uint32_t(sizes.size());
    pool_info.pPoolSizes = sizes.data();
    Check(vkCreateDescriptorPool(d.device, &pool_info, nullptr, &descriptor_pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    set_info.descriptorPool = descriptor_pool;
    set_info.descriptorSetCount = 1;
    set_info.pSetLayouts = &p.set_layout;
    VkDescriptorSet set;
    Check(vkAllocateDescriptorSets(d.device, &set_info, &set), "vkAllocateDescriptorSets");

    VkDescriptorImageInfo image_infos[kTextureCount];
    VkDescriptorBufferInfo buffer_infos[2] = {{input_buffer.buffer, 0, VK_WHOLE_SIZE},
                                              {output_buffer.buffer, 0, VK_WHOLE_SIZE}};
    VkDescriptorImageInfo sampler_info{d.sampler, VK_NULL_HANDLE, VK_IMAGE_LAYOUT_UNDEFINED};
    std::vector<VkWriteDescriptorSet> writes;
    for (int i = 0; i < kTextureCount; ++i) {
      image_infos[i] = {combined ? d.sampler : VK_NULL_HANDLE, d.textures[i].view,
                        VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = set;
      w.dstBinding = uint32_t(i);
      w.descriptorCount = 1;
      w.descriptorType = p.bindings[i].descriptorType;
      w.pImageInfo = &image_infos[i];
      writes.push_back(w);
    }
    for (int k = 0; k < 2; ++k) {
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = set;
      w.dstBinding = uint32_t(k == 0 ? kInputBinding : kOutputBinding);
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w.pBufferInfo = &buffer_infos[k];
      writes.push_back(w);
    }
    if (!combined) {
      VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w.dstSet = set;
      w.dstBinding = uint32_t(kSamplerBinding);
      w.descriptorCount = 1;
      w.descriptorType = VK_DESCRIPTOR_TYPE_SAMPLER;
      w.pImageInfo = &sampler_info;
      writes.push_back(w);
    }
    vkUpdateDescriptorSets(d.device, uint32_t(writes.size()), writes.data(), 0, nullptr);

    const double seconds = d.Submit([&](VkCommandBuffer commands) {
      vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
      vkCmdBindDescriptorSets(commands, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &set, 0, nullptr);
      vkCmdDispatch(commands, uint32_t((items + 63) / 64), 1, 1);
      VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &barrier,
                           0, nullptr, 0, nullptr);
    });
    if (outputs) {
      outputs->resize(items);
      void* mapped;
      Check(vkMapMemory(d.device, output_buffer.memory, 0, output_buffer.size, 0, &mapped), "vkMapMemory");
      std::memcpy(outputs->data(), mapped, output_buffer.size);
      vkUnmapMemory(d.device, output_buffer.memory);
    }
    release();
    return seconds;
  } catch (...) {
    release();
    throw;
  }
}

std::string VulkanCompute::Description() const { return impl_->description; }

#else  // !SKYBAKE_HAVE_VULKAN

struct VulkanCompute::Impl {};

std::unique_ptr<VulkanCompute> VulkanCompute::Create(std::string* why_not) {
  *why_not = "built without the Vulkan headers and loader (libvulkan-dev)";
  return nullptr;
}
void VulkanCompute::SetTexture(int, int, int, int, const float*, std::size_t) {}
std::vector<std::array<float, 4>> VulkanCompute::Run(const std::vector<std::uint32_t>&, Samplers,
                                                    const std::vector<std::array<float, 4>>&, std::size_t) {
  return {};
}
int VulkanCompute::CreatePipeline(const std::vector<std::uint32_t>&, Samplers, double*) {
  throw std::runtime_error("built without Vulkan");
}
double VulkanCompute::TimeDispatch(int, const std::vector<std::array<float, 4>>&, std::size_t,
                                   std::vector<std::array<float, 4>>*) {
  throw std::runtime_error("built without Vulkan");
}
std::string VulkanCompute::Description() const { return {}; }

#endif

std::vector<std::uint32_t> CompileComputeShader(const std::string& compiler, const std::string& source, bool hlsl,
                                                std::string* log) {
  namespace fs = std::filesystem;
  std::random_device random;
  const fs::path dir = fs::temp_directory_path() / ("skybake_spirv_" + std::to_string(random()));
  fs::create_directories(dir);
  struct Remove {
    fs::path dir;
    ~Remove() {
      std::error_code ignored;
      fs::remove_all(dir, ignored);
    }
  } remove{dir};
  const fs::path file = dir / "shader", spirv = dir / "shader.spv", output = dir / "log.txt";
  std::ofstream(file, std::ios::binary) << source;
  const std::string command = "'" + compiler + "' -V --target-env vulkan1.1 -S comp " + (hlsl ? "-D -e main " : "") +
                              "-o '" + spirv.string() + "' '" + file.string() + "' > '" + output.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream log_file(output);
  log->assign(std::istreambuf_iterator<char>(log_file), std::istreambuf_iterator<char>());
  if (status != 0) return {};
  std::ifstream in(spirv, std::ios::binary);
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::uint32_t> words(bytes.size() / 4);
  std::memcpy(words.data(), bytes.data(), words.size() * 4);
  return words;
}

VulkanCompute::VulkanCompute() : impl_(std::make_unique<Impl>()) {}
VulkanCompute::~VulkanCompute() = default;

}  // namespace skybake
