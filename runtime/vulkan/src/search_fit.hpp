// Whether a VulkanSearch fits the device, checked in create() before
// anything is allocated, so that a database or a batch too large for the
// device is an error naming the limit and the sizes (rather than a failed
// allocation half-way through, or a descriptor range the driver would
// silently clamp):
//  - the database's texel buffers against maxTexelBufferElements, and their
//    bytes against the device-local memory heap;
//  - each per-slot storage buffer (max_batch queries) against
//    maxStorageBufferRange, and all slots against the host-visible heap.
// The limits are the Context's (ContextOptions::limit_caps lowers them).
#pragma once

#include <cstdint>

#include "kernel_shape.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan::detail {

// Bytes of each per-slot storage buffer but the scratch (sized later, from
// the kernel): the one place these sizes are computed.
struct SlotBufferBytes {
  std::uint64_t queries = 0;  // [max_batch x dim_vec4s] vec4
  std::uint64_t params = 0;   // [max_batch] QueryGpu
  std::uint64_t weights = 0;  // [max_batch x channels] float
  std::uint64_t results = 0;  // [max_batch x k class] uvec2
};
SlotBufferBytes slot_buffer_bytes(const KernelShape& shape, const VulkanSearchOptions& options);

Status check_search_fits(const Context& context, const KernelShape& shape, const VulkanSearchOptions& options);

}  // namespace mmvk::vulkan::detail
