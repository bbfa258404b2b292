// The Vulkan entries of the backend registry (mmvk/backends.hpp):
// vulkan-brute (VulkanBruteForce), vulkan-clusters and vulkan-nprobe
// (VulkanClusterSearch, nprobe 0 and spec.nprobe), made on `context`.
//
//   mmvk::BackendRegistry registry = mmvk::cpu_backends();
//   MMVK_TRY(mmvk::vulkan::add_backends(registry, context));
#pragma once

#include <functional>

#include "mmvk/backends.hpp"
#include "mmvk/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"  // VulkanSearchOptions

namespace mmvk::vulkan {

// Where the backends are made: a context that outlives the registry and
// every backend made from it. The source is called each time a backend is
// made, so a host can create its context only when a Vulkan backend is
// asked for (listing the names needs no device).
using ContextSource = std::function<Result<Context*>()>;

// `context` must outlive the registry and every backend made from it.
// `base` supplies the options a BackendSpec does not carry (slots,
// rows_per_invocation, scratch_bytes, force_staging_upload); the search
// and its nprobe come from the name, max_batch, max_k, max_tile and
// warm_up from the spec.
// Error when one of the names is already registered.
Status add_backends(BackendRegistry& registry, Context& context, const VulkanSearchOptions& base = {});
Status add_backends(BackendRegistry& registry, ContextSource context, const VulkanSearchOptions& base = {});

}  // namespace mmvk::vulkan
