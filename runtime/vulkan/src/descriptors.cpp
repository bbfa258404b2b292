#include "descriptors.hpp"

#include <array>
#include <string>
#include <vector>

#include "check.hpp"

namespace mmvk::vulkan::detail {

Status check_binding_limits(const Context& context, std::span<const SetShape> sets, std::string_view kernels) {
  SetShape total;
  for (const SetShape& set : sets) {
    total.texel += set.texel;
    total.storage += set.storage;
  }
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  // Texel buffers count against the sampled-image limit.
  if (limits.maxBoundDescriptorSets < sets.size() || limits.maxPerStageDescriptorStorageBuffers < total.storage ||
      limits.maxPerStageDescriptorSampledImages < total.texel || limits.maxPerStageResources < total.bindings()) {
    return make_error("Vulkan: the device allows too few descriptors per stage for the " + std::string(kernels) +
                      " (" + std::to_string(sets.size()) + " set(s), " + std::to_string(total.storage) +
                      " storage buffers and " + std::to_string(total.texel) + " texel buffers needed)");
  }
  return {};
}

Result<UniqueDescriptorSetLayout> create_set_layout(const Context& context, SetShape shape) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(shape.bindings());
  for (std::uint32_t b = 0; b < shape.bindings(); ++b) {
    bindings[b].binding = b;
    bindings[b].descriptorType =
        b < shape.texel ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  info.bindingCount = shape.bindings();
  info.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateDescriptorSetLayout(context.device(), &info, nullptr, &layout));
  return UniqueDescriptorSetLayout(context.device(), layout);
}

Result<UniqueDescriptorPool> create_descriptor_pool(const Context& context, SetShape shape, std::uint32_t set_count) {
  const std::array<VkDescriptorPoolSize, 2> sizes = {{
      {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, shape.texel * set_count},
      {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, shape.storage * set_count},
  }};
  VkDescriptorPoolCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  info.maxSets = set_count;
  info.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  info.pPoolSizes = sizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateDescriptorPool(context.device(), &info, nullptr, &pool));
  return UniqueDescriptorPool(context.device(), pool);
}

Result<VkDescriptorSet> allocate_set(const Context& context, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                     std::span<const VkBufferView> texels, std::span<const VkBuffer> storage) {
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = pool;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkAllocateDescriptorSets(context.device(), &allocate, &set));

  const auto texel_count = static_cast<std::uint32_t>(texels.size());
  const auto binding_count = static_cast<std::uint32_t>(texels.size() + storage.size());
  std::vector<VkDescriptorBufferInfo> infos(storage.size());
  std::vector<VkWriteDescriptorSet> writes(binding_count);
  for (std::uint32_t b = 0; b < binding_count; ++b) {
    VkWriteDescriptorSet& w = writes[b];
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = set;
    w.dstBinding = b;
    w.descriptorCount = 1;
    if (b < texel_count) {
      w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
      w.pTexelBufferView = &texels[b];
    } else {
      infos[b - texel_count] = {storage[b - texel_count], 0, VK_WHOLE_SIZE};
      w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      w.pBufferInfo = &infos[b - texel_count];
    }
  }
  vkUpdateDescriptorSets(context.device(), binding_count, writes.data(), 0, nullptr);
  return set;
}

}  // namespace mmvk::vulkan::detail
