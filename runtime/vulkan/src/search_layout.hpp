// The C++ side of shaders/search_layout.glsl: the structs the kernels read,
// declared once per side, next to each other, with their sizes and offsets
// checked here. Change both files together.
#pragma once

#include <cstddef>
#include <cstdint>

#include "descriptors.hpp"

namespace mmvk::vulkan::detail {

// GLSL: QueryGpu (std430 array element).
struct QueryGpu {
  std::uint32_t continuing_frame;  // kNoFrame: none
  std::uint32_t exclusion_window;
  std::uint32_t require_lo;
  std::uint32_t require_hi;
  std::uint32_t exclude_lo;
  std::uint32_t exclude_hi;
  std::uint32_t window_clip;  // clip of the continuing frame, kNoFrame when no window applies
  std::uint32_t clip_first;
  std::uint32_t clip_count;
  std::uint32_t clip_loop;
  float continuing_bias;
  float continuing_multiplier;
  std::uint32_t continuing_row;  // the continuing frame's feature-matrix row (scan_rows.hpp: feature_row())
  // The rows the scans skip (scan rows in brute-force mode, frames in the
  // cluster modes), (first, last - first) twice, (kNoFrame, 0) when empty
  // (scan_rows.hpp: skipped_scan_rows()).
  std::uint32_t skip_first_a;
  std::uint32_t skip_span_a;
  std::uint32_t skip_first_b;
  std::uint32_t skip_span_b;
};
static_assert(sizeof(QueryGpu) == 68);
// 32-bit words of a QueryGpu (the cluster kernels read them as R32UI texels;
// GLSL: kQueryGpuWords in cluster_layout.glsl).
inline constexpr std::uint32_t kQueryGpuWords = sizeof(QueryGpu) / 4;
static_assert(kQueryGpuWords == 17);
static_assert(offsetof(QueryGpu, window_clip) == 24);
static_assert(offsetof(QueryGpu, continuing_bias) == 40);
static_assert(offsetof(QueryGpu, continuing_multiplier) == 44);
static_assert(offsetof(QueryGpu, continuing_row) == 48);
static_assert(offsetof(QueryGpu, skip_span_b) == 64);

// GLSL: SearchPush (push constants of every search kernel).
struct SearchPush {
  std::uint32_t scan_rows;  // rows of the scan_frames buffer
  std::uint32_t rows_per_invocation;
  std::uint32_t block_count;
  std::uint32_t query_base;
  std::uint32_t query_count;
  std::uint32_t pad[3];  // GLSL: pad0, pad1, pad2
};
static_assert(sizeof(SearchPush) == 32);
static_assert(sizeof(SearchPush) <= 128, "Vulkan guarantees only 128 bytes of push constants");
static_assert(offsetof(SearchPush, query_count) == 16);

// GLSL: kRowGroup. The feature texels are interleaved in groups of this many
// consecutive rows, [frame / kRowGroup][dim_vec4s][frame % kRowGroup]
// (feature_texel() in search_layout.glsl), so that the lanes of a subgroup
// that scan consecutive rows read one contiguous run of texels per vec4.
inline constexpr std::uint32_t kRowGroup = 8;

// The texel of (frame, vec4 v) in that layout, for dim_vec4s vec4s a row.
constexpr std::uint64_t feature_texel(std::uint64_t frame, std::uint32_t v, std::uint32_t dim_vec4s) {
  return ((frame / kRowGroup) * dim_vec4s + v) * kRowGroup + frame % kRowGroup;
}

// Descriptor bindings of set 0 (search_layout.glsl).
enum Binding : std::uint32_t {
  kBindingFeatures = 0,   // uniform texel buffer, RGBA32F, rows interleaved by kRowGroup
  kBindingFrameMeta = 1,  // uniform texel buffer, RGBA32UI
  kBindingFrameCost = 2,  // uniform texel buffer, RG32F
  kBindingScanFrames = 3, // uniform texel buffer, R32UI
  kBindingScanTerms = 4,  // uniform texel buffer, RGBA32UI
  kBindingQueries = 5,    // storage buffer
  kBindingParams = 6,     // storage buffer
  kBindingWeights = 7,    // storage buffer
  kBindingScratch = 8,    // storage buffer
  kBindingResults = 9,    // storage buffer
  kBindingCount = 10,
};
inline constexpr SetShape kSearchSet{5, 5};
static_assert(kSearchSet.texel == kBindingQueries && kSearchSet.bindings() == kBindingCount);

}  // namespace mmvk::vulkan::detail
