// Compute pipelines from the embedded SPIR-V (shaders/ registry), with
// specialization constants, their layouts, and the one dispatch() helper
// (direct and indirect, any push-constant struct) that checks every
// dispatch against the device limits before recording it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

#include "handles.hpp"
#include "memory.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

// The SPIR-V of shaders/<name>.comp, or an error naming it.
Result<std::span<const std::uint32_t>> shader_code(std::string_view name);

struct SpecValue {
  std::uint32_t id;
  std::uint32_t value;
};

Result<UniquePipeline> create_compute_pipeline(const Context& context, VkPipelineLayout layout, std::string_view shader,
                                               std::span<const SpecValue> spec);

// A pipeline layout of `sets` (set i = sets[i]) and one compute push-constant
// range of `push_bytes` from offset 0, checked against maxPushConstantsSize.
// The error names `kernels`.
Result<UniquePipelineLayout> create_pipeline_layout(const Context& context, std::span<const VkDescriptorSetLayout> sets,
                                                    std::uint32_t push_bytes, std::string_view kernels);

// A push-constant struct as the kernels read it: plain 32-bit words, within
// the 128 bytes every Vulkan device allows (each struct also static_asserts
// its layout next to its GLSL twin).
template <class Push>
concept PushConstants = std::is_trivially_copyable_v<Push> && std::is_standard_layout_v<Push> &&
                        sizeof(Push) % 4 == 0 && sizeof(Push) <= 128;

// Records bind + push constants + dispatch; type-erased halves of the
// templates below.
Status record_dispatch(const Context& context, VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                       std::span<const std::byte> push, std::uint32_t groups_x, std::uint32_t groups_y,
                       std::string_view kernel);
Status record_dispatch_indirect(const Context& context, VkCommandBuffer commands, VkPipeline pipeline,
                                VkPipelineLayout layout, std::span<const std::byte> push, const Buffer& arguments,
                                VkDeviceSize offset, std::uint64_t max_groups_x, std::string_view kernel);

// Records push constants + vkCmdDispatch after checking the group counts
// against maxComputeWorkGroupCount and the push constants against
// maxPushConstantsSize; the error names the kernel.
template <PushConstants Push>
Status dispatch(const Context& context, VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                const Push& push, std::uint32_t groups_x, std::uint32_t groups_y, std::string_view kernel) {
  return record_dispatch(context, commands, pipeline, layout, std::as_bytes(std::span<const Push, 1>(&push, 1)),
                         groups_x, groups_y, kernel);
}

// Records push constants + vkCmdDispatchIndirect of the VkDispatchIndirectCommand
// at `offset` in `arguments`, which the GPU writes: the caller passes the
// most x groups it can hold (y and z are 1), checked against the device's
// limit, and the command must lie inside the buffer.
template <PushConstants Push>
Status dispatch_indirect(const Context& context, VkCommandBuffer commands, VkPipeline pipeline,
                         VkPipelineLayout layout, const Push& push, const Buffer& arguments, VkDeviceSize offset,
                         std::uint64_t max_groups_x, std::string_view kernel) {
  return record_dispatch_indirect(context, commands, pipeline, layout,
                                  std::as_bytes(std::span<const Push, 1>(&push, 1)), arguments, offset, max_groups_x,
                                  kernel);
}

}  // namespace mmvk::vulkan::detail
