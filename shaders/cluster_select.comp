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
//    clusters whose box holds the query tie at 0), and the next one; lists
//    for scan round 0 the two blocks of least bound among theirs (with
//    k = 1 and a continuing frame, of those whose bound is <= its cost).
//    Their best gives round 1's upper bound: all the seed cluster's blocks
//    (15 a query, 256 rows each) gave a bound little better, and their rows
//    were a quarter of those visited (Bandai volume set, transition).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "cluster_bound.glsl"
#include "cluster_blocks.glsl"

// Of the blocks of clusters a and b (b may be kNone), the two of least
// (bound key, block) whose key is <= upper, kNone where there are fewer.
// At most the two clusters' block count iterations.
uvec2 least_blocks(uint a, uint b, uint upper, vec4 q[DV], float w[CHANNELS]) {
  const uint a_first = texelFetch(cluster_info, int(a * 3u)).w;
  const uint a_blocks = texelFetch(cluster_info, int(a * 3u + 2u)).z - a_first;
  const uint b_first = b == kNone ? 0u : texelFetch(cluster_info, int(b * 3u)).w;
  const uint b_blocks = b == kNone ? 0u : texelFetch(cluster_info, int(b * 3u + 2u)).z - b_first;
  uvec2 keys = uvec2(kSkip, kSkip);
  uvec2 blocks = uvec2(kNone, kNone);
  for (uint i = 0u; i < a_blocks + b_blocks; ++i) {
    const uint block = i < a_blocks ? a_first + i : b_first + (i - a_blocks);
    const uint key = block_key(block, q, w);
    if (key == kSkip || key > upper) continue;
    const bool first = blocks.x == kNone || key < keys.x || (key == keys.x && block < blocks.x);
    const bool second = !first && (blocks.y == kNone || key < keys.y || (key == keys.y && block < blocks.y));
    keys.y = first ? keys.x : second ? key : keys.y;
    blocks.y = first ? blocks.x : second ? block : blocks.y;
    keys.x = first ? key : keys.x;
    blocks.x = first ? block : blocks.x;
  }
  return blocks;
}

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

  // The two eligible clusters of least (centroid distance, id).
  uint seed = kNone;
  uint seed_distance = kSkip;
  uint seed2 = kNone;
  uint seed2_distance = kSkip;
  for (uint c = 0u; c < clusters; ++c) {
    const uvec2 keys = bound_keys[base + c];
    const bool eligible = keys.x != kSkip;
    const bool first = eligible && (seed == kNone || keys.y < seed_distance);
    const bool second = eligible && !first && (seed2 == kNone || keys.y < seed2_distance);
    seed2_distance = first ? seed_distance : second ? keys.y : seed2_distance;
    seed2 = first ? seed : second ? c : seed2;
    seed_distance = first ? keys.y : seed_distance;
    seed = first ? c : seed;
  }

  const uvec2 continuing = continuing_pair(query);
  uvec2 items = uvec2(0u, 0u);
  uvec2 seed_blocks = uvec2(kNone, kNone);
  if (seed != kNone) {
    vec4 q[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    const uint upper = pc.k == 1u && continuing.y != kNone ? continuing.x : kSkip;
    seed_blocks = least_blocks(seed, seed2, upper, q, w);
    const uint row = local_query * pc.block_count;
    uint count = 0u;
    if (seed_blocks.x != kNone) listed[row + count++] = seed_blocks.x;
    if (seed_blocks.y != kNone) listed[row + count++] = seed_blocks.y;
    items = move_listed(0u, local_query, count);
  }
  states[query].seed = seed;
  states[query].seed_blocks = seed_blocks;
  states[query].continuing_pair = continuing;
  states[query].items0 = items;
}
