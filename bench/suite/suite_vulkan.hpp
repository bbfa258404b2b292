// The suite's backends and its Vulkan side: one HostBackends per process
// (host/crowd/backends/host_backends.hpp, where the hosts make theirs), whose
// Vulkan context is created only when a Vulkan cell runs (a CPU-only filter
// never touches the driver). Without Vulkan in the build the vulkan-* cells
// are absent.
#pragma once

#include "backends/host_backends.hpp"
#include "mmvk/search/search.hpp"

namespace mmvk::vulkan {
class VulkanSearch;
}

namespace mmvk::bench {

// Constructs the suite's backends (their context is made later). Call it
// before creating anything that may own Vulkan backends, so the context is
// destroyed after them at exit.
void prepare_vulkan_context();

// The suite's backends; the first Vulkan backend made prints its device.
crowd::HostBackends& suite_backends();

// Says which device the suite's Vulkan cells run on, once per process.
void note_vulkan_device(const SearchBackend& backend);

// The backend as a VulkanSearch, or nullptr.
vulkan::VulkanSearch* as_vulkan_search(SearchBackend& backend);

// GPU seconds of `search`'s last submit from timestamps; 0 when unknown.
double last_kernel_seconds(const vulkan::VulkanSearch& search);

}  // namespace mmvk::bench
