// Cluster search, pass 3 (twice per chunk, indirect): kRowLanes invocations
// per work item (member block, query) evaluate the block's rows (lane i: rows i, i +
// kRowLanes, ...) and write the query's best K (key, frame) pairs of their
// rows to block_pairs. The lanes of a SIMD group share one block, so they
// are all active or all pruned (one invocation per block left 7 of 8 lanes
// idle on lavapipe: 1 visited block in 8 is typical).
//  round 0: the blocks of the query's seed cluster (listed by
//           cluster_select);
//  round 1: the blocks of every other cluster whose bound key is <= the
//           k-th best key after round 0 (listed by cluster_merge round 0;
//           strictly greater cannot win, equal may still win on a lower
//           frame id). Pruned blocks write nothing: the merge reads only
//           visited blocks.
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

void main() {
  const uint item = gl_GlobalInvocationID.x / kRowLanes;
  const uint lane = gl_GlobalInvocationID.x % kRowLanes;
  if (item >= scan_dispatch[pc.round].w) return;
  const uvec2 work = work_items[item];
  const uint local_query = work.x;
  const uint block = work.y;
  const uint query = pc.query_base + local_query;
  const uvec4 info = texelFetch(block_info, int(block));

  vec4 q[DV];
  float w[CHANNELS];
  load_query(query, q, w);
  const QueryGpu p = query_params[query];
  uvec2 best[K];
  clear_pairs(best);
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
  const uint out_base = ((local_query * pc.block_count + block) * kRowLanes + lane) * K;
  [[unroll]] for (uint j = 0; j < K; ++j) block_pairs[out_base + j] = best[j];
}
