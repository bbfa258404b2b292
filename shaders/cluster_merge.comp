// Cluster search, pass 4 (twice per chunk): one invocation per query merges
// the continuing frame's pair and the per-lane best pairs of the visited
// blocks into the query's best K, in the strict (cost, frame) order.
//  round 0: the seed cluster's blocks; writes the k-th best key as the
//           upper bound of round 1 (kSkip while fewer than k were found)
//           and lists the blocks of the other clusters whose bound key is
//           <= it for scan round 1.
//  round 1: every visited block (the seed's, and those whose cluster bound
//           key is <= the upper bound); writes the results and the number
//           of rows evaluated. The loops run at most block_count x
//           (kRowLanes + 1) + cluster_count iterations (capped for
//           llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;
  const uint query = pc.query_base + local_query;
  const ClusterQueryState state = states[query];

  uvec2 best[K];
  clear_pairs(best);
  insert_pair(best, state.continuing_pair);
  const uint pair_base = local_query * pc.block_count;

  if (pc.round == 0u) {
    if (state.seed != kNone) {
      const uint first = texelFetch(cluster_info, int(state.seed * 3u)).w;
      const uint end = texelFetch(cluster_info, int(state.seed * 3u + 2u)).z;
      for (uint lane_list = first * kRowLanes; lane_list < end * kRowLanes; ++lane_list) {
        [[unroll]] for (uint i = 0; i < K; ++i) insert_pair(best, block_pairs[(pair_base * kRowLanes + lane_list) * K + i]);
      }
    }
    uint upper = kSkip;
    [[unroll]] for (uint j = 0; j < K; ++j) {
      if (j + 1u == pc.k && best[j].y != kNone) upper = best[j].x;
    }
    states[query].upper_key = upper;
    const uint key_base = local_query * pc.cluster_count;
    for (uint c = 0u; c < pc.cluster_count; ++c) {
      const uint key = bound_keys[key_base + c].x;
      if (c == state.seed || key == kSkip || key > upper) continue;
      const uint first = texelFetch(cluster_info, int(c * 3u)).w;
      const uint end = texelFetch(cluster_info, int(c * 3u + 2u)).z;
      for (uint b = first; b < end; ++b) append_work(1u, local_query, b);
    }
    return;
  }

  uint rows = state.continuing_pair.y != kNone ? 1u : 0u;
  const uint key_base = local_query * pc.cluster_count;
  for (uint b = 0u; b < pc.block_count; ++b) {
    const uvec4 info = texelFetch(block_info, int(b));
    bool visited = info.x == state.seed;
    if (!visited) {
      const uint key = bound_keys[key_base + info.x].x;
      visited = key != kSkip && key <= state.upper_key;
    }
    if (visited) {
      rows += info.z - info.y;
      for (uint lane = 0u; lane < kRowLanes; ++lane) {
        const uint at = ((pair_base + b) * kRowLanes + lane) * K;
        [[unroll]] for (uint i = 0; i < K; ++i) insert_pair(best, block_pairs[at + i]);
      }
    }
  }
  [[unroll]] for (uint j = 0; j < K; ++j) results[query * K + j] = best[j];
  states[query].rows = rows;
}
