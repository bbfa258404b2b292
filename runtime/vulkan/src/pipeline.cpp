#include "pipeline.hpp"

#include <string>
#include <vector>

#include "check.hpp"
#include "mmvk_shaders/registry.hpp"

namespace mmvk::vulkan::detail {

Result<std::span<const std::uint32_t>> shader_code(std::string_view name) {
  for (const shaders::ShaderCode& code : shaders::kAll) {
    if (code.name == name) return std::span<const std::uint32_t>(code.words, code.word_count);
  }
  return make_error("Vulkan: no embedded shader named '" + std::string(name) + "'");
}

Result<UniquePipeline> create_compute_pipeline(const Context& context, VkPipelineLayout layout, std::string_view shader,
                                               std::span<const SpecValue> spec) {
  Result<std::span<const std::uint32_t>> code = shader_code(shader);
  if (!code) return code.error();
  const VkDevice device = context.device();
  VkShaderModuleCreateInfo module_info{};
  module_info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  module_info.codeSize = code->size() * sizeof(std::uint32_t);
  module_info.pCode = code->data();
  VkShaderModule module_handle = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateShaderModule(device, &module_info, nullptr, &module_handle));
  const UniqueShaderModule module(device, module_handle);

  std::vector<VkSpecializationMapEntry> entries;
  std::vector<std::uint32_t> values;
  for (const SpecValue& v : spec) {
    entries.push_back({v.id, static_cast<std::uint32_t>(values.size() * sizeof(std::uint32_t)), sizeof(std::uint32_t)});
    values.push_back(v.value);
  }
  VkSpecializationInfo spec_info{};
  spec_info.mapEntryCount = static_cast<std::uint32_t>(entries.size());
  spec_info.pMapEntries = entries.data();
  spec_info.dataSize = values.size() * sizeof(std::uint32_t);
  spec_info.pData = values.data();

  VkComputePipelineCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module_handle;
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = &spec_info;
  info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline));
  return UniquePipeline(device, pipeline);
}

Status check_binding_limits(const Context& context) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (limits.maxPerStageDescriptorStorageBuffers < kStorageBindings ||
      limits.maxPerStageDescriptorSampledImages < kTexelBindings || limits.maxBoundDescriptorSets < 1 ||
      limits.maxPerStageResources < kBindingCount) {
    return make_error("Vulkan: the device allows too few descriptors per stage for the search kernels (" +
                      std::to_string(kStorageBindings) + " storage buffers and " + std::to_string(kTexelBindings) +
                      " texel buffers needed)");
  }
  return {};
}

Status dispatch(const Context& context, VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                const SearchPush& push, std::uint32_t groups_x, std::uint32_t groups_y, std::string_view kernel) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (groups_x == 0 || groups_y == 0) return make_error("Vulkan: empty dispatch of " + std::string(kernel));
  if (groups_x > limits.maxComputeWorkGroupCount[0] || groups_y > limits.maxComputeWorkGroupCount[1]) {
    return make_error("Vulkan: dispatch of " + std::string(kernel) + " with " + std::to_string(groups_x) + " x " +
                      std::to_string(groups_y) + " workgroups exceeds maxComputeWorkGroupCount (" +
                      std::to_string(limits.maxComputeWorkGroupCount[0]) + " x " +
                      std::to_string(limits.maxComputeWorkGroupCount[1]) + ")");
  }
  if (sizeof(SearchPush) > limits.maxPushConstantsSize) {
    return make_error("Vulkan: " + std::string(kernel) + " needs " + std::to_string(sizeof(SearchPush)) +
                      " bytes of push constants, the device allows " + std::to_string(limits.maxPushConstantsSize));
  }
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdPushConstants(commands, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(SearchPush), &push);
  vkCmdDispatch(commands, groups_x, groups_y, 1);
  return {};
}

Result<UniqueDescriptorSetLayout> create_set_layout(const Context& context, std::uint32_t binding_count,
                                                    std::uint32_t texel_bindings) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(binding_count);
  for (std::uint32_t b = 0; b < binding_count; ++b) {
    bindings[b].binding = b;
    bindings[b].descriptorType =
        b < texel_bindings ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  info.bindingCount = binding_count;
  info.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateDescriptorSetLayout(context.device(), &info, nullptr, &layout));
  return UniqueDescriptorSetLayout(context.device(), layout);
}

}  // namespace mmvk::vulkan::detail
