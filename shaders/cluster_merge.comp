// Cluster search, pass 4 (twice per chunk): one invocation per query merges
// the continuing frame's pair and the per-lane best pairs of its work items
// into the query's best K, in the strict (cost, frame) order.
//  round 0: the seed cluster's items; the k-th best key is the upper bound
//           of round 1 (kSkip while fewer than k were found); lists, of the
//           other clusters whose bound key is <= it, the blocks whose own
//           bound key is <= it (block-level culling: a block's box is much
//           tighter than its cluster's) for scan round 1.
//  round 1: the items of both rounds; writes the results and the number of
//           rows evaluated.
// The loops run at most cluster_count + 2 x block_count iterations per
// invocation (capped for llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "cluster_bound.glsl"
#include "cluster_blocks.glsl"
#include "top_k.glsl"

// Inserts the per-lane pairs of work items [items.x, items.x + items.y);
// returns the rows they evaluated.
uint merge_items(inout uvec2 best[K], uvec2 items) {
  uint rows = 0u;
  for (uint item = items.x; item < items.x + items.y; ++item) {
    [[unroll]] for (uint i = 0; i < K; ++i) insert_pair(best, block_pairs[item * K + i]);
    const uvec4 info = texelFetch(block_info, int(work_items[item].y * 2u));
    rows += info.z - info.y;
  }
  return rows;
}

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;
  const uint query = pc.query_base + local_query;
  const ClusterQueryState state = states[query];

  uvec2 best[K];
  clear_pairs(best);
  insert_pair(best, state.continuing_pair);
  uint rows = merge_items(best, state.items0);

  if (pc.round == 0u) {
    uint upper = kSkip;
    [[unroll]] for (uint j = 0; j < K; ++j) {
      if (j + 1u == pc.k && best[j].y != kNone) upper = best[j].x;
    }
    states[query].upper_key = upper;
    vec4 q[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    uint count = 0u;
    const uint key_base = local_query * pc.cluster_count;
    for (uint c = 0u; c < pc.cluster_count; ++c) {
      const uint key = bound_keys[key_base + c].x;
      if (c == state.seed || key == kSkip || key > upper) continue;
      const uint first = texelFetch(cluster_info, int(c * 3u)).w;
      const uint end = texelFetch(cluster_info, int(c * 3u + 2u)).z;
      count = list_blocks(local_query, first, end, upper, count, q, w);
    }
    states[query].items1 = move_listed(1u, local_query, count);
    return;
  }

  rows += merge_items(best, state.items1);
  rows += state.continuing_pair.y != kNone ? 1u : 0u;
  [[unroll]] for (uint j = 0; j < K; ++j) results[query * K + j] = best[j];
  states[query].rows = rows;
}
