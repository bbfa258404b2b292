#include "search_fit.hpp"

#include <algorithm>
#include <string>

#include "search_layout.hpp"

namespace mmvk::vulkan::detail {

namespace {

// The heap of the first memory type with all of `flags` (drivers list the
// preferred types first, as create_buffer picks them); heap 0 when none.
std::uint32_t heap_of(const VkPhysicalDeviceMemoryProperties& memory, VkMemoryPropertyFlags flags) {
  for (std::uint32_t t = 0; t < memory.memoryTypeCount; ++t) {
    if ((memory.memoryTypes[t].propertyFlags & flags) == flags) return memory.memoryTypes[t].heapIndex;
  }
  return 0;
}

Status check_heap(const Context& context, VkMemoryPropertyFlags flags, std::uint64_t bytes, const std::string& what) {
  const VkPhysicalDeviceMemoryProperties& memory = context.memory_properties();
  const std::uint32_t heap = heap_of(memory, flags);
  const VkDeviceSize size = memory.memoryHeaps[heap].size;
  if (bytes <= size) return {};
  return make_error("VulkanSearch: " + what + " needs " + std::to_string(bytes) + " bytes of device memory, more than the " +
                    std::to_string(size) + " bytes of memory heap " + std::to_string(heap) + " of '" +
                    context.device_name() + "'");
}

}  // namespace

SlotBufferBytes slot_buffer_bytes(const KernelShape& shape, const VulkanSearchOptions& options) {
  const std::uint64_t batch = options.max_batch;
  SlotBufferBytes bytes;
  bytes.queries = batch * shape.dim_vec4s * 16;
  bytes.params = batch * sizeof(QueryGpu);
  bytes.weights = batch * std::max(shape.channels, 1u) * sizeof(float);
  bytes.results = batch * k_class(options.max_k) * 8;
  return bytes;
}

Status check_search_fits(const Context& context, const KernelShape& shape, const VulkanSearchOptions& options) {
  const VkPhysicalDeviceLimits& limits = context.properties().limits;
  const std::uint64_t frames = shape.frame_count;

  // The database: three texel buffers in device-local memory.
  // The feature rows are interleaved in whole groups of kRowGroup.
  const std::uint64_t padded_frames = (frames + kRowGroup - 1) / kRowGroup * kRowGroup;
  const std::uint64_t feature_texels = padded_frames * shape.dim_vec4s;
  if (feature_texels > limits.maxTexelBufferElements) {
    return make_error("VulkanSearch: the feature matrix (" + std::to_string(frames) + " frames, " +
                      std::to_string(padded_frames) + " in groups of " + std::to_string(kRowGroup) + ", x " +
                      std::to_string(shape.dim_vec4s) + " texels) needs " + std::to_string(feature_texels) +
                      " texels, over the device's maxTexelBufferElements of " +
                      std::to_string(limits.maxTexelBufferElements) + "; use a smaller database");
  }
  const std::uint64_t database_bytes = feature_texels * 16 + frames * 16 + frames * 8 + std::max(shape.scan_rows, 1u) * 20;
  MMVK_TRY(check_heap(context, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, database_bytes,
                      "the database (" + std::to_string(frames) + " frames x " + std::to_string(shape.dims) + " dims)"));

  // One submission slot: storage buffers for max_batch queries.
  const SlotBufferBytes slot = slot_buffer_bytes(shape, options);
  const struct {
    std::uint64_t bytes;
    std::uint64_t per_query;
    const char* what;
  } buffers[] = {
      {slot.queries, slot.queries / options.max_batch, "the query buffer"},
      {slot.params, slot.params / options.max_batch, "the query parameter buffer"},
      {slot.weights, slot.weights / options.max_batch, "the weight buffer"},
      {slot.results, slot.results / options.max_batch, "the result buffer"},
  };
  for (const auto& buffer : buffers) {
    if (buffer.bytes <= limits.maxStorageBufferRange) continue;
    return make_error("VulkanSearch: " + std::string(buffer.what) + " for max_batch = " +
                      std::to_string(options.max_batch) + " queries needs " + std::to_string(buffer.bytes) +
                      " bytes, over the device's maxStorageBufferRange of " +
                      std::to_string(limits.maxStorageBufferRange) + " bytes; lower max_batch to at most " +
                      std::to_string(limits.maxStorageBufferRange / buffer.per_query));
  }
  const std::uint64_t slot_bytes = slot.queries + slot.params + slot.weights + slot.results +
                                   std::min<std::uint64_t>(options.scratch_bytes, limits.maxStorageBufferRange);
  return check_heap(context, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                    options.slots * slot_bytes,
                    std::to_string(options.slots) + " submission slots of max_batch = " +
                        std::to_string(options.max_batch) + " queries");
}

}  // namespace mmvk::vulkan::detail
