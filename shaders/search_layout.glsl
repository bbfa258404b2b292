// The data layout shared by the search kernels: descriptor bindings, the
// per-query parameter struct and the push constants. The C++ side of every
// struct here is in runtime/vulkan/src/search_layout.hpp, with static_asserts
// on its size and offsets; change both together.
#ifndef MMVK_SEARCH_LAYOUT_GLSL
#define MMVK_SEARCH_LAYOUT_GLSL

const uint kNone = 0xFFFFFFFFu;

// Per-frame flag bits (mmvk::FrameFlag).
const uint kFrameDoNotUse = 1u;
const uint kFrameBlockTransition = 2u;
const uint kFrameEdgeExcluded = 4u;

// search_layout.hpp: QueryGpu (68 bytes, std430).
struct QueryGpu {
  uint continuing_frame;   // kNone: no continuing frame
  uint exclusion_window;
  uint require_lo;
  uint require_hi;
  uint exclude_lo;
  uint exclude_hi;
  uint window_clip;        // clip of the continuing frame, kNone when no window applies
  uint clip_first;         // that clip's first frame
  uint clip_count;         // that clip's frame count
  uint clip_loop;          // 1 when that clip loops
  float continuing_bias;
  float continuing_multiplier;
  uint continuing_row;     // the continuing frame's row of `features`
  // The rows the scans skip (scan rows in brute-force mode, frames in the
  // cluster modes), (first, last - first) twice, (kNone, 0) when empty: the
  // continuing frame and its exclusion window.
  uint skip_first_a;
  uint skip_span_a;
  uint skip_first_b;
  uint skip_span_b;
};

// search_layout.hpp: SearchPush (32 bytes). Kernels with their own push
// constants (the cluster kernels) define MMVK_SEARCH_LAYOUT_OWN_PUSH.
#ifndef MMVK_SEARCH_LAYOUT_OWN_PUSH
layout(push_constant) uniform SearchPush {
  uint scan_rows;          // rows of scan_frames
  uint rows_per_invocation;
  uint block_count;        // scan invocations (kernel_shape.hpp: KernelShape::block_count)
  uint query_base;         // first query of this chunk in the query buffers
  uint query_count;        // queries in this chunk
  uint pad0;
  uint pad1;
  uint pad2;
} pc;
#endif

// search_layout.hpp: kRowGroup. The feature matrix's rows are interleaved in
// groups of kRowGroup consecutive rows, [frame / kRowGroup][dims/4][frame %
// kRowGroup]: lanes that scan consecutive rows read consecutive texels
// (coalesced on a GPU; on lavapipe a gather from one 128-byte run, which the
// hardware prefetcher follows, instead of 8 streams).
const uint kRowGroup = 8u;

// [ceil(frames / kRowGroup) x dims/4 x kRowGroup] texels: the feature matrix,
// dims padded to 4 with zeros, rows interleaved (feature_texel()); rows past
// the last frame are zeros. Row r is frame r, except in brute-force mode:
// the scan rows first, in scan_frames' order, then the other frames
// (runtime/vulkan/src/scan_rows.hpp); QueryGpu.continuing_row says where
// the continuing frame is.
layout(set = 0, binding = 0) uniform samplerBuffer features;
// [frames] texels: (flags, tags low 32 bits, tags high 32 bits, clip index).
layout(set = 0, binding = 1) uniform usamplerBuffer frame_meta;
// [frames] texels: (cost multiplier, cost bias).
layout(set = 0, binding = 2) uniform samplerBuffer frame_cost;
// [scan rows] texels: the frames the brute-force scan visits (every frame
// that can be a candidate other than as a continuing frame), ascending.
layout(set = 0, binding = 3) uniform usamplerBuffer scan_frames;
// [scan rows] texels, in scan_frames' order: what the scan needs of each of
// those frames, (tags low, tags high, cost multiplier bits, cost bias bits),
// in one fetch that does not wait for the frame's index.
layout(set = 0, binding = 4) uniform usamplerBuffer scan_terms;
// [max_batch x dims/4] query features, padded like the rows.
layout(std430, set = 0, binding = 5) readonly buffer Queries { vec4 query_features[]; };
// [max_batch] query parameters.
layout(std430, set = 0, binding = 6) readonly buffer Params { QueryGpu query_params[]; };
// [max_batch x channels] channel weights (non-empty channels only).
layout(std430, set = 0, binding = 7) readonly buffer Weights { float query_weights[]; };
// The query accessors every kernel reads its queries through: here over
// the storage buffers; a layout that defines MMVK_QUERY_TEXELS before
// including this file (cluster_layout.glsl) defines them over texel views
// of the same buffers. Need DV and CHANNELS (kernel_shape.glsl).
#ifndef MMVK_QUERY_TEXELS
vec4 query_feature(uint query, uint v) { return query_features[query * DV + v]; }
float query_weight(uint query, uint c) { return query_weights[query * CHANNELS + c]; }
QueryGpu query_params_of(uint query) { return query_params[query]; }
#endif
// [chunk queries x blocks x K] per-block best (key, frame) pairs.
layout(std430, set = 0, binding = 8) buffer Scratch { uvec2 scratch[]; };
// [max_batch x max_k] final best (key, frame) pairs, sorted.
layout(std430, set = 0, binding = 9) writeonly buffer Results { uvec2 results[]; };

// A (cost, frame) pair as (orderable cost bits, frame): unsigned comparison
// of the key follows float order, negative costs included.
uint orderable_bits(float cost) {
  uint bits = floatBitsToUint(cost);
  if (cost == 0.0) bits = 0u;  // -0.0 and +0.0 compare equal in the reference
  return (bits & 0x80000000u) != 0u ? ~bits : bits | 0x80000000u;
}

// The cost a key was made from (+0.0 for a zero cost).
float cost_of_key(uint key) {
  return uintBitsToFloat((key & 0x80000000u) != 0u ? key & 0x7FFFFFFFu : ~key);
}

// Strict (cost, frame) order; an empty slot is (kNone, kNone) and loses to
// every candidate, an infinite cost included.
bool pair_less(uvec2 a, uvec2 b) {
  return a.x < b.x || (a.x == b.x && a.y < b.y);
}

#endif
