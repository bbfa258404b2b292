#include "memory.hpp"

#include <cstring>
#include <optional>
#include <string>

#include "check.hpp"
#include "commands.hpp"

namespace mmvk::vulkan::detail {

namespace {

std::optional<std::uint32_t> find_type(const VkPhysicalDeviceMemoryProperties& props, std::uint32_t allowed,
                                       VkMemoryPropertyFlags required) {
  // Drivers list types best first, so the first match is the one to use.
  for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((allowed & (1u << i)) != 0 && (props.memoryTypes[i].propertyFlags & required) == required) return i;
  }
  return std::nullopt;
}

}  // namespace

Result<Buffer> create_buffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use,
                             const char* what) {
  const VkDevice device = context.device();
  if (context.max_memory_allocation_size() != 0 && size > context.max_memory_allocation_size()) {
    return make_error(std::string("Vulkan: ") + what + " needs " + std::to_string(size) +
                      " bytes, over the device's maxMemoryAllocationSize of " +
                      std::to_string(context.max_memory_allocation_size()));
  }
  Buffer result;
  result.size = size;
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
  UniqueBuffer owned_buffer(device, buffer);

  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(device, buffer, &requirements);
  const VkPhysicalDeviceMemoryProperties& props = context.memory_properties();
  std::optional<std::uint32_t> type;
  if (use == MemoryUse::DeviceLocal) {
    type = find_type(props, requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (!type) type = find_type(props, requirements.memoryTypeBits, 0);
  } else {
    const VkMemoryPropertyFlags visible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    type = find_type(props, requirements.memoryTypeBits, visible | VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    if (!type) type = find_type(props, requirements.memoryTypeBits, visible);
  }
  if (!type) return make_error(std::string("Vulkan: no suitable memory type for ") + what);

  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = *type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  const VkResult allocated = vkAllocateMemory(device, &allocate, nullptr, &memory);
  if (allocated != VK_SUCCESS) {
    return make_error(std::string("Vulkan: allocating ") + std::to_string(requirements.size) + " bytes for " + what +
                      " failed: " + vk_error(allocated, "vkAllocateMemory", __FILE__, __LINE__).message);
  }
  result.memory = UniqueMemory(device, memory);
  result.buffer = std::move(owned_buffer);
  MMVK_VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));

  const VkMemoryPropertyFlags flags = props.memoryTypes[*type].propertyFlags;
  if ((flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0) {
    MMVK_VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &result.mapped));
    result.coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    // Touches every page now: on unified memory (lavapipe) the pages are
    // otherwise faulted in by the first search that reaches them, which
    // made the first search of a process measurably slower than later ones.
    // Only coherent memory: a non-coherent host write could be written back
    // over what the device wrote later.
    if (result.coherent) std::memset(result.mapped, 0, size);
  }
  return result;
}

Status upload(const Context& context, VkCommandPool pool, Buffer& destination, std::span<const std::byte> data) {
  if (data.size() > destination.size) return make_error("Vulkan: upload larger than its buffer");
  if (data.empty()) return {};
  const VkDevice device = context.device();
  if (destination.mapped != nullptr) {
    std::memcpy(destination.mapped, data.data(), data.size());
    if (!destination.coherent) {
      VkMappedMemoryRange range{};
      range.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE;
      range.memory = destination.memory.get();
      range.size = VK_WHOLE_SIZE;
      MMVK_VK_CHECK(vkFlushMappedMemoryRanges(device, 1, &range));
    }
    return {};
  }

  Result<Buffer> staging = create_buffer(context, data.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryUse::HostMapped,
                                         "the staging buffer");
  if (!staging) return staging.error();
  std::memcpy(staging->mapped, data.data(), data.size());

  VkCommandBufferAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  allocate.commandPool = pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer commands = VK_NULL_HANDLE;
  MMVK_VK_CHECK(vkAllocateCommandBuffers(device, &allocate, &commands));
  // Frees the command buffer on every return path.
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer commands;
    ~Free() { vkFreeCommandBuffers(device, pool, 1, &commands); }
  } free_commands{device, pool, commands};

  MMVK_TRY(begin_one_time(commands));
  VkBufferCopy copy{0, 0, data.size()};
  vkCmdCopyBuffer(commands, staging->buffer.get(), destination.buffer.get(), 1, &copy);
  // Makes the copy visible to every later compute dispatch on this queue.
  memory_barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  MMVK_VK_CHECK(vkEndCommandBuffer(commands));
  MMVK_ASSIGN_OR_RETURN(const UniqueFence fence, create_fence(context));
  const VkFence fence_handle = fence.get();
  MMVK_TRY(submit(context, commands, fence_handle));
  MMVK_VK_CHECK(vkWaitForFences(device, 1, &fence_handle, VK_TRUE, UINT64_MAX));
  return {};
}

}  // namespace mmvk::vulkan::detail
