// A Database in device-local memory, in the layout the kernels read:
//  features   [ceil(frames / kRowGroup) x dims/4 x kRowGroup] RGBA32F texels,
//             dims padded to 4 with zeros, rows interleaved in groups of
//             kRowGroup (search_layout.hpp: feature_texel()), zero rows past
//             the last frame; row f is frame f, or with the scan the scan
//             rows first (scan_rows.hpp: feature_row())
//  frame_meta [frames] RGBA32UI texels (flags, tags low, tags high, clip)
//  frame_cost [frames] RG32F texels (cost multiplier, cost bias)
//  scan_frames [scan rows] R32UI texels: the frames the brute-force scan
//             visits, ascending (scanned_by_brute_force())
//  scan_terms [scan rows] RGBA32UI texels, in scan_frames' order: (tags low,
//             tags high, cost multiplier bits, cost bias bits)
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
#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan::detail {

struct TexelBuffer {
  Buffer buffer;          // before `view`: the view is destroyed first
  UniqueBufferView view;
};

// Whether the brute-force scan visits a frame with these FrameFlag bits: a
// do-not-use, edge-excluded or block-transition frame is a candidate only as
// a continuing frame, which the merge pass evaluates on its own (the CPU
// tile store leaves the same rows out of its tiles).
constexpr bool scanned_by_brute_force(std::uint32_t flags) {
  return (flags & (kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition)) == 0;
}

// The number of frames of `database` the brute-force scan visits.
std::uint32_t scan_row_count(const Database& database);

struct DeviceDatabase {
  std::uint32_t frame_count = 0;
  std::uint32_t scan_rows = 0;  // frames in scan_frames
  std::uint32_t dims = 0;
  std::uint32_t dim_vec4s = 0;  // ceil(dims / 4)
  TexelBuffer features;
  TexelBuffer frame_meta;
  TexelBuffer frame_cost;
  TexelBuffer scan_frames;  // at least one texel, even with no scan rows
  TexelBuffer scan_terms;   // as many texels as scan_frames
  std::vector<std::uint32_t> scan_rows_before;  // host: scan_rows.hpp, scan_rows_before(); empty without the scan
};

// force_staging: copy through a staging buffer even into mappable memory.
template <class T>
std::span<const std::byte> bytes_of(const std::vector<T>& values) {
  return std::as_bytes(std::span<const T>(values));
}

// A uniform texel view of the first `bytes` of `buffer` (created with
// VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT), after checking the texel count
// against maxTexelBufferElements and the format's support; `what` names the
// data in errors.
Result<UniqueBufferView> create_texel_view(const Context& context, const Buffer& buffer, VkFormat format,
                                           std::uint32_t texel_bytes, std::uint64_t bytes, const char* what);

// A device-local texel buffer of `format` holding `data` (uploaded through
// staging when the memory is not host-visible, or when force_staging), and
// its view. `what` names the data in errors, e.g. over maxTexelBufferElements.
Result<TexelBuffer> make_texel_buffer(const Context& context, VkCommandPool pool, VkFormat format,
                                      std::uint32_t texel_bytes, std::span<const std::byte> data, const char* what,
                                      bool force_staging);

// with_scan: fill scan_frames and scan_terms and put the scan rows first in
// features (the brute force); else they hold one unused texel each.
Result<DeviceDatabase> upload_database(const Context& context, VkCommandPool pool, const Database& database,
                                       bool with_scan, bool force_staging);

}  // namespace mmvk::vulkan::detail
