// A Database in device-local memory, in the layout the kernels read:
//  features   [ceil(frames / kRowGroup) x dims/4 x kRowGroup] RGBA32F texels,
//             dims padded to 4 with zeros, rows interleaved in groups of
//             kRowGroup (search_layout.hpp: feature_texel()), zero rows past
//             the last frame
//  frame_meta [frames] RGBA32UI texels (flags, tags low, tags high, clip)
//  frame_cost [frames] RG32F texels (cost multiplier, cost bias)
// Texel buffers, not storage buffers: texelFetch is a vectorized gather on
// lavapipe, and maxTexelBufferElements (128 Mi texels there) is far above
// maxStorageBufferRange (128 MiB).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "handles.hpp"
#include "memory.hpp"
#include "mmvk/database.hpp"
#include "mmvk/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

struct TexelBuffer {
  Buffer buffer;          // before `view`: the view is destroyed first
  UniqueBufferView view;
};

struct DeviceDatabase {
  std::uint32_t frame_count = 0;
  std::uint32_t dims = 0;
  std::uint32_t dim_vec4s = 0;  // ceil(dims / 4)
  TexelBuffer features;
  TexelBuffer frame_meta;
  TexelBuffer frame_cost;
};

// force_staging: copy through a staging buffer even into mappable memory.
template <class T>
std::span<const std::byte> bytes_of(const std::vector<T>& values) {
  return std::as_bytes(std::span<const T>(values));
}

// A device-local texel buffer of `format` holding `data` (uploaded through
// staging when the memory is not host-visible, or when force_staging), and
// its view. `what` names the data in errors, e.g. over maxTexelBufferElements.
Result<TexelBuffer> make_texel_buffer(const Context& context, VkCommandPool pool, VkFormat format,
                                      std::uint32_t texel_bytes, std::span<const std::byte> data, const char* what,
                                      bool force_staging);

Result<DeviceDatabase> upload_database(const Context& context, VkCommandPool pool, const Database& database,
                                       bool force_staging);

}  // namespace mmvk::vulkan::detail
