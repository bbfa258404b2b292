// Cluster search, pass 3 (twice per chunk, indirect): one invocation per
// work item (query, member block) evaluates the block's rows and writes the
// query's best K (key, frame) pairs of the block at the item's place in
// block_pairs. The work items are dense (only visited blocks are listed),
// so the lanes of a SIMD group are all busy, on different blocks (an
// earlier layout split a block over 8 lanes and merged them through shared
// memory and a barrier: 1.35x slower end to end on lavapipe).
//  round 0: the seed cluster's blocks (listed by cluster_select);
//  round 1: the blocks, of every other cluster, whose bound key is <= the
//           k-th best key after round 0 (listed by cluster_merge round 0).
// Rows are read in cluster order (member_rows: a block's rows are
// contiguous) and evaluated with the brute-force scan's arithmetic and
// candidate rules (search_cost.glsl); the continuing frame is skipped
// (cluster_select evaluated it with its bias). The row loop runs at most
// rows_per_block iterations (llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

void main() {
  const uint local_item = gl_GlobalInvocationID.x;
  if (local_item >= scan_dispatch[pc.round].w) return;
  const uint item = (pc.round == 0u ? 0u : scan_dispatch[0].w) + local_item;
  const uvec2 work = work_items[item];
  const uint query = pc.query_base + work.x;
  const uvec4 info = texelFetch(block_info, int(work.y * 2u));
  vec4 q[DV];
  float w[CHANNELS];
  load_query(query, q, w);
  const QueryGpu p = query_params[query];
  // The candidate rules as in the brute force, branch-free: flagged rows get
  // a NaN bias, the tags and the exclusion window (which holds the
  // continuing frame, evaluated by cluster_select) are integer operations.
  const uvec4 skipped = skipped_ranges(p);
  // K = 1: the running best; a frame of kNone is an empty slot. Rows run in
  // descending frame order (a block's members ascend), so `cost <= best`
  // keeps the lowest frame among ties, accepts an infinite cost into an
  // empty slot and rejects NaN.
  float best_cost = uintBitsToFloat(0x7F800000u);
  uint best_frame = kNone;
  // K > 1: the best K, sorted, and the cost of the last (+inf while empty).
  uvec2 best[K];
  clear_pairs(best);
  float worst = uintBitsToFloat(0x7F800000u);
  for (uint m = info.z; m > info.y;) {
    --m;
    const uvec4 meta = texelFetch(member_meta, int(m));  // (frame, flags, tags lo, tags hi)
    const uint r = meta.x;
    vec2 scale_bias = texelFetch(member_cost, int(m)).xy;
    if ((meta.y & kNeverCandidate) != 0u) scale_bias.y = uintBitsToFloat(0x7FC00000u);
    vec4 x[DV];
    [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(member_rows, int(m * DV + v));
    const float cost = row_cost(x, q, w, scale_bias);
    const uint rejected = ((meta.z & p.require_lo) ^ p.require_lo) | ((meta.w & p.require_hi) ^ p.require_hi) |
                          (meta.z & p.exclude_lo) | (meta.w & p.exclude_hi) |
                          uint(r - skipped.x <= skipped.y) | uint(r - skipped.z <= skipped.w);
    if (K == 1u) {
      const bool better = rejected == 0u && cost <= best_cost;
      best_cost = better ? cost : best_cost;
      best_frame = better ? r : best_frame;
    } else if (rejected == 0u && !(cost > worst)) {
      insert_row(best, worst, cost, r);
    }
  }
  if (K == 1u) {
    block_pairs[item] = best_frame == kNone ? uvec2(kNone, kNone) : uvec2(orderable_bits(best_cost), best_frame);
  } else {
    [[unroll]] for (uint j = 0; j < K; ++j) block_pairs[item * K + j] = best[j];
  }
}
