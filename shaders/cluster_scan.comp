// Cluster search, pass 3 (twice per chunk, indirect): kRowLanes invocations
// per work item (query, member block) evaluate the block's rows (lane i:
// rows i, i + kRowLanes, ...); lane 0 merges the lanes' best K (key, frame)
// pairs through shared memory and writes the item's best K to block_pairs
// at the item's place (the merge then reads K pairs per item: with
// kRowLanes x K its loops ran past llvmpipe's limit at K = 16). The lanes of
// a SIMD group share one block, so they are all in_range or all idle (one
// invocation per block left 7 of 8 lanes idle on lavapipe).
//  round 0: the seed cluster's blocks (listed by cluster_select);
//  round 1: the blocks, of every other cluster, whose bound key is <= the
//           k-th best key after round 0 (listed by cluster_merge round 0).
// Rows are evaluated with the brute-force scan's arithmetic
// (search_cost.glsl); the continuing frame is skipped (cluster_select
// evaluated it with its bias). The row loop runs at most rows_per_block
// / kRowLanes iterations (llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

// Every lane's best K, for lane 0 of its item.
shared uvec2 lane_pairs[kScanWorkgroup * K];

void main() {
  const uint local_item = gl_GlobalInvocationID.x / kRowLanes;
  const uint lane = gl_GlobalInvocationID.x % kRowLanes;
  const uint slot = gl_LocalInvocationID.x * K;
  // No early return before the barrier (uniform control flow).
  const bool in_range = local_item < scan_dispatch[pc.round].w;
  const uint item = (pc.round == 0u ? 0u : scan_dispatch[0].w) + local_item;
  uvec2 best[K];
  clear_pairs(best);
  if (in_range) {
    const uvec2 work = work_items[item];
    const uint query = pc.query_base + work.x;
    const uvec4 info = texelFetch(block_info, int(work.y * 2u));
    vec4 q[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    const QueryGpu p = query_params[query];
    float worst = uintBitsToFloat(0x7F800000u);  // cost of best[K - 1], +inf while empty
    for (uint m = info.y + lane; m < info.z; m += kRowLanes) {
      const uint r = texelFetch(members, int(m)).x;
      const uvec4 meta = texelFetch(frame_meta, int(r));
      vec4 x[DV];
      [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(features, int(r * DV + v));
      const float cost = row_cost(x, q, w, texelFetch(frame_cost, int(r)).xy);
      // One float compare first (NaN and ties pass it), as the brute force.
      if (!(cost > worst) && r != p.continuing_frame && frame_is_candidate(r, meta, false, p)) {
        insert_row(best, worst, cost, r);
      }
    }
  }
  [[unroll]] for (uint j = 0; j < K; ++j) lane_pairs[slot + j] = best[j];
  barrier();
  if (!in_range || lane != 0u) return;
  for (uint other = 1u; other < kRowLanes; ++other) {
    [[unroll]] for (uint j = 0; j < K; ++j) insert_pair(best, lane_pairs[slot + other * K + j]);
  }
  [[unroll]] for (uint j = 0; j < K; ++j) block_pairs[item * K + j] = best[j];
}
