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
  MMVK_VK_CHECK(vkCreateComputePipelines(device, context.pipeline_cache(), 1, &info, nullptr, &pipeline));
  return UniquePipeline(device, pipeline);
}

Result<UniquePipelineLayout> create_pipeline_layout(const Context& context, std::span<const VkDescriptorSetLayout> sets,
                                                    std::uint32_t push_bytes, std::string_view kernels) {
  const std::uint32_t allowed = context.properties().limits.maxPushConstantsSize;
  if (push_bytes > allowed) {
    return make_error("Vulkan: the " + std::string(kernels) + " need " + std::to_string(push_bytes) +
                      " bytes of push constants, the device allows " + std::to_string(allowed));
  }
  const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
  VkPipelineLayoutCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  info.setLayoutCount = static_cast<std::uint32_t>(sets.size());
  info.pSetLayouts = sets.data();
  info.pushConstantRangeCount = 1;
  info.pPushConstantRanges = &push;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreatePipelineLayout(context.device(), &info, nullptr, &layout));
  return UniquePipelineLayout(context.device(), layout);
}

namespace {

Status check_push(const Context& context, std::span<const std::byte> push, std::string_view kernel) {
  const std::uint32_t allowed = context.properties().limits.maxPushConstantsSize;
  if (push.size() > allowed) {
    return make_error("Vulkan: " + std::string(kernel) + " needs " + std::to_string(push.size()) +
                      " bytes of push constants, the device allows " + std::to_string(allowed));
  }
  return {};
}

void bind_and_push(VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                   std::span<const std::byte> push) {
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
  vkCmdPushConstants(commands, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, static_cast<std::uint32_t>(push.size()),
                     push.data());
}

}  // namespace

Status record_dispatch(const Context& context, VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                       std::span<const std::byte> push, std::uint32_t groups_x, std::uint32_t groups_y,
                       std::string_view kernel) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (groups_x == 0 || groups_y == 0) return make_error("Vulkan: empty dispatch of " + std::string(kernel));
  if (groups_x > limits.maxComputeWorkGroupCount[0] || groups_y > limits.maxComputeWorkGroupCount[1]) {
    return make_error("Vulkan: dispatch of " + std::string(kernel) + " with " + std::to_string(groups_x) + " x " +
                      std::to_string(groups_y) + " workgroups exceeds maxComputeWorkGroupCount (" +
                      std::to_string(limits.maxComputeWorkGroupCount[0]) + " x " +
                      std::to_string(limits.maxComputeWorkGroupCount[1]) + ")");
  }
  MMVK_TRY(check_push(context, push, kernel));
  bind_and_push(commands, pipeline, layout, push);
  vkCmdDispatch(commands, groups_x, groups_y, 1);
  return {};
}

Status record_dispatch_indirect(const Context& context, VkCommandBuffer commands, VkPipeline pipeline,
                                VkPipelineLayout layout, std::span<const std::byte> push, const Buffer& arguments,
                                VkDeviceSize offset, std::uint64_t max_groups_x, std::string_view kernel) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  if (max_groups_x > limits.maxComputeWorkGroupCount[0]) {
    return make_error("Vulkan: indirect dispatch of " + std::string(kernel) + " with up to " +
                      std::to_string(max_groups_x) + " workgroups may exceed maxComputeWorkGroupCount (" +
                      std::to_string(limits.maxComputeWorkGroupCount[0]) + ")");
  }
  if (offset % 4 != 0 || offset + sizeof(VkDispatchIndirectCommand) > arguments.size) {
    return make_error("Vulkan: the indirect arguments of " + std::string(kernel) + " at offset " +
                      std::to_string(offset) + " do not lie in their " + std::to_string(arguments.size) +
                      "-byte buffer (or are not 4-byte aligned)");
  }
  MMVK_TRY(check_push(context, push, kernel));
  bind_and_push(commands, pipeline, layout, push);
  vkCmdDispatchIndirect(commands, arguments.buffer.get(), offset);
  return {};
}

}  // namespace mmvk::vulkan::detail
