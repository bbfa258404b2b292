// Compute pipelines from the embedded SPIR-V (shaders/ registry), with
// specialization constants, and the one dispatch() helper that checks every
// dispatch against the device limits before recording it.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <utility>

#include "gpu_layout.hpp"
#include "handles.hpp"
#include "mmvk/status.hpp"
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

// Checks the descriptor counts of the search layout against the device's
// per-stage limits.
Status check_binding_limits(const Context& context);

// A compute descriptor set layout of `binding_count` single bindings: the
// first `texel_bindings` uniform texel buffers, the rest storage buffers.
Result<UniqueDescriptorSetLayout> create_set_layout(const Context& context, std::uint32_t binding_count,
                                                    std::uint32_t texel_bindings);

// Records push constants + vkCmdDispatch after checking the group counts
// against maxComputeWorkGroupCount and the push constants against
// maxPushConstantsSize; the error names the kernel.
Status dispatch(const Context& context, VkCommandBuffer commands, VkPipeline pipeline, VkPipelineLayout layout,
                const SearchPush& push, std::uint32_t groups_x, std::uint32_t groups_y, std::string_view kernel);

}  // namespace mmvk::vulkan::detail
