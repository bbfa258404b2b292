// Small command-buffer steps shared by the upload and the searches, each
// written once: a global memory barrier, a one-time begin, a fence and a
// submit that signals it.
#pragma once

#include <vulkan/vulkan.h>

#include "handles.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

// Makes `src_access` writes in `src_stages` visible to `dst_access` in
// `dst_stages` (one VkMemoryBarrier: mmvk never needs finer ones).
void memory_barrier(VkCommandBuffer commands, VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                    VkPipelineStageFlags dst_stages, VkAccessFlags dst_access);

// vkBeginCommandBuffer for one submission.
Status begin_one_time(VkCommandBuffer commands);

// An unsignalled fence.
Result<UniqueFence> create_fence(const Context& context);

// Submits `commands` to the context's queue; `fence` signals on completion.
Status submit(const Context& context, VkCommandBuffer commands, VkFence fence);

}  // namespace mmvk::vulkan::detail
