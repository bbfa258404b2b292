// The suite's Vulkan side: one Context per process, created only when a
// Vulkan cell runs (a CPU-only filter never touches the driver). Without
// Vulkan in the build these do nothing and the vulkan-* cells are absent.
#pragma once

#include "mmvk/backends.hpp"

namespace mmvk::vulkan {
class VulkanSearch;
}

namespace mmvk::bench {

// Constructs the (empty) holder of the context. Call it before creating
// anything that may own Vulkan backends, so the context is destroyed after
// them at exit.
void prepare_vulkan_context();

// Adds vulkan-brute, vulkan-clusters and vulkan-nprobe on the shared
// context (created on the first make()); a failure is printed and the
// registry keeps its CPU entries.
void add_vulkan_backends(BackendRegistry& registry);

// The backend as a VulkanSearch, or nullptr.
vulkan::VulkanSearch* as_vulkan_search(SearchBackend& backend);

// GPU seconds of `search`'s last submit from timestamps; 0 when unknown.
double last_kernel_seconds(const vulkan::VulkanSearch& search);

}  // namespace mmvk::bench
