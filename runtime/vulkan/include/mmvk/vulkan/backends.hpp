// The Vulkan entries of the backend registry (mmvk/search/backends.hpp):
// vulkan-brute (VulkanBruteForce), vulkan-clusters and vulkan-nprobe
// (VulkanClusterSearch, nprobe 0 and spec.nprobe), made on `context`.
//
//   mmvk::BackendRegistry registry = mmvk::cpu_backends();
//   mmvk::vulkan::VulkanSearchOptions options;
//   options.max_batch = 256;
//   MMVK_TRY(mmvk::vulkan::add_backends(registry, context, options));
#pragma once

#include <functional>

#include "mmvk/search/backends.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"  // VulkanSearchOptions

namespace mmvk::vulkan {

// Where the backends are made: a context that outlives the registry and
// every backend made from it. The source is called each time a backend is
// made, so a host can create its context only when a Vulkan backend is
// asked for (listing the names needs no device).
using ContextSource = std::function<Result<Context*>()>;

// `context` must outlive the registry and every backend made from it.
// `options` are the made searches' own (max_batch, max_k, max_tile,
// warm_up, slots, ...: the device's side, which BackendSpec does not
// carry); the search and its nprobe come from the name and the spec, the
// cluster table from spec.clusters or spec.kmeans.
// Error when one of the names is already registered.
Status add_backends(BackendRegistry& registry, Context& context, const VulkanSearchOptions& base = {});
Status add_backends(BackendRegistry& registry, ContextSource context, const VulkanSearchOptions& base = {});

}  // namespace mmvk::vulkan
