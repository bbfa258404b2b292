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
// Rows are evaluated with the brute-force scan's arithmetic
// (search_cost.glsl); the continuing frame is skipped (cluster_select
// evaluated it with its bias). The row loop runs at most rows_per_block
// iterations (llvmpipe's loop limit).
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
  uvec2 best[K];
  clear_pairs(best);
  float worst = uintBitsToFloat(0x7F800000u);  // cost of best[K - 1], +inf while empty
  for (uint m = info.y; m < info.z; ++m) {
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
  [[unroll]] for (uint j = 0; j < K; ++j) block_pairs[item * K + j] = best[j];
}
