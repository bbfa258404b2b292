// Buffers with their own memory, chosen by use:
//  - DeviceLocal: read by the kernels; filled once through staging, or
//    directly when the device-local type is also host-visible (unified
//    memory: integrated GPUs, lavapipe).
//  - HostMapped: written or read by the host on every search; persistently
//    mapped, coherent (cached when available, for read-back).
#pragma once

#include <cstddef>
#include <span>

#include "handles.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

enum class MemoryUse { DeviceLocal, HostMapped };

struct Buffer {
  UniqueMemory memory;  // before `buffer`: the buffer is destroyed first
  UniqueBuffer buffer;
  VkDeviceSize size = 0;
  void* mapped = nullptr;  // non-null when host-visible (always for HostMapped)
  bool coherent = false;
};

// `what` names the buffer in error messages.
Result<Buffer> create_buffer(const Context& context, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use,
                             const char* what);

// Copies `data` to the start of a DeviceLocal buffer: directly when it is
// mapped, else through a temporary staging buffer and a one-time command
// buffer from `pool` (waits for completion).
Status upload(const Context& context, VkCommandPool pool, Buffer& destination, std::span<const std::byte> data);

}  // namespace mmvk::vulkan::detail
