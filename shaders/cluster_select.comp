// Cluster search, pass 2: one invocation per query.
//  - nprobe mode: keeps the bound keys of the nprobe eligible clusters with
//    the least (centroid distance, cluster id) and sets the others to kSkip
//    (the threshold is found by a binary search over the 32-bit distance
//    keys: 32 counting loops over the clusters, so cluster_count is capped
//    for llvmpipe's loop limit).
//  - evaluates the continuing frame (cost with continuing_multiplier and
//    continuing_bias), which the cluster scans skip, as ClusterSearch seeds it;
//  - picks the seed: the eligible cluster of least (centroid distance, id),
//    ClusterSearch's seed_nearest (the least bound was a worse seed: many
//    clusters whose box holds the query tie at 0), and lists its blocks for
//    scan round 0: with k = 1 only those whose bound is <= the continuing
//    frame's cost, else all.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "cluster_bound.glsl"
#include "cluster_blocks.glsl"

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;
  const uint query = pc.query_base + local_query;
  const uint base = local_query * pc.cluster_count;
  const uint clusters = pc.cluster_count;

  if (pc.nprobe != 0u) {
    uint eligible = 0u;
    for (uint c = 0u; c < clusters; ++c) eligible += bound_keys[base + c].x != kSkip ? 1u : 0u;
    if (eligible > pc.nprobe) {
      // The least T with count(distance key <= T) >= nprobe (ineligible
      // clusters have distance key kSkip, above every T tried).
      uint lo = 0u;
      uint hi = kSkip - 1u;
      for (uint step = 0u; step < 32u && lo < hi; ++step) {
        const uint mid = lo + ((hi - lo) >> 1u);
        uint n = 0u;
        for (uint c = 0u; c < clusters; ++c) n += bound_keys[base + c].y <= mid ? 1u : 0u;
        if (n >= pc.nprobe) {
          hi = mid;
        } else {
          lo = mid + 1u;
        }
      }
      uint below = 0u;
      for (uint c = 0u; c < clusters; ++c) below += bound_keys[base + c].y < lo ? 1u : 0u;
      uint take = pc.nprobe - below;  // clusters at exactly the threshold, by ascending id
      for (uint c = 0u; c < clusters; ++c) {
        const uint distance = bound_keys[base + c].y;
        bool keep = distance < lo;
        if (distance == lo && take > 0u) {
          keep = true;
          --take;
        }
        if (!keep) bound_keys[base + c].x = kSkip;
      }
    }
  }

  uint seed = kNone;
  uint seed_distance = kSkip;
  for (uint c = 0u; c < clusters; ++c) {
    const uvec2 keys = bound_keys[base + c];
    if (keys.x != kSkip && (seed == kNone || keys.y < seed_distance)) {
      seed_distance = keys.y;
      seed = c;
    }
  }

  const uvec2 continuing = continuing_pair(query);
  uvec2 items = uvec2(0u, 0u);
  if (seed != kNone) {
    vec4 q[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    const uint upper = pc.k == 1u && continuing.y != kNone ? continuing.x : kSkip;
    const uint first = texelFetch(cluster_info, int(seed * 3u)).w;
    const uint end = texelFetch(cluster_info, int(seed * 3u + 2u)).z;
    items = move_listed(0u, local_query, list_blocks(local_query, first, end, upper, 0u, q, w));
  }
  states[query].seed = seed;
  states[query].continuing_pair = continuing;
  states[query].items0 = items;
}
