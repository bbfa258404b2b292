// Descriptor sets of the compute kernels. Every set mmvk uses has the same
// shape: uniform texel buffers at bindings [0, texel), storage buffers after
// them (search_layout.glsl, cluster_layout.glsl), so a SetShape says all
// that the layout, the pool, the limit check and the writes need.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "handles.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

struct SetShape {
  std::uint32_t texel = 0;    // uniform texel buffers, bindings [0, texel)
  std::uint32_t storage = 0;  // storage buffers, bindings [texel, texel + storage)
  constexpr std::uint32_t bindings() const { return texel + storage; }
};

// Checks that the device can bind `sets` together (set i = sets[i]) in one
// compute stage: maxBoundDescriptorSets and the per-stage descriptor
// counts. The error names `kernels`.
Status check_binding_limits(const Context& context, std::span<const SetShape> sets, std::string_view kernels);

// The compute descriptor set layout of `shape`, one descriptor per binding.
Result<UniqueDescriptorSetLayout> create_set_layout(const Context& context, SetShape shape);

// A pool for `set_count` sets of `shape` (freed as a whole with the pool).
Result<UniqueDescriptorPool> create_descriptor_pool(const Context& context, SetShape shape, std::uint32_t set_count);

// Allocates one set of `layout` (made from the shape {texels.size(),
// storage.size()}) from `pool` and points it at `texels` and at the whole
// of each `storage` buffer. Written once: the set is reused every search.
Result<VkDescriptorSet> allocate_set(const Context& context, VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                     std::span<const VkBufferView> texels, std::span<const VkBuffer> storage);

}  // namespace mmvk::vulkan::detail
