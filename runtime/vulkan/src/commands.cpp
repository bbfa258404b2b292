#include "commands.hpp"

#include <optional>

#include "check.hpp"

namespace mmvk::vulkan::detail {

void memory_barrier(VkCommandBuffer commands, VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                    VkPipelineStageFlags dst_stages, VkAccessFlags dst_access) {
  VkMemoryBarrier barrier{};
  barrier.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  barrier.srcAccessMask = src_access;
  barrier.dstAccessMask = dst_access;
  vkCmdPipelineBarrier(commands, src_stages, dst_stages, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

Status begin_one_time(VkCommandBuffer commands) {
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  MMVK_VK_CHECK(vkBeginCommandBuffer(commands, &begin));
  return {};
}

Result<UniqueFence> create_fence(const Context& context) {
  VkFenceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkFence fence = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateFence(context.device(), &info, nullptr, &fence));
  return UniqueFence(context.device(), fence);
}

Status submit(const Context& context, VkCommandBuffer commands, VkFence fence) {
  VkSubmitInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  info.commandBufferCount = 1;
  info.pCommandBuffers = &commands;
  if (context.device_lost()) return context.device_lost_error();
  // An injected fault stands for a submit that failed: nothing is queued.
  const std::optional<VkResult> fault = context.take_injected_fault("vkQueueSubmit");
  const VkResult result = fault ? *fault : vkQueueSubmit(context.queue(), 1, &info, fence);
  return watched(context, result, "vkQueueSubmit", "vkQueueSubmit(queue, 1, &info, fence)", __FILE__, __LINE__);
}

}  // namespace mmvk::vulkan::detail
