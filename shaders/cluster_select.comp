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
//    clusters whose box holds the query tie at 0), and the next nearest
//    ones (kSeedClusters in all); lists for scan round 0 the kSeedBlocks (4)
//    blocks of least bound among theirs (with k = 1 and a continuing
//    frame, of those whose bound is <= its cost). Their best gives round
//    1's upper bound. Scanning every block of the nearest clusters (about
//    15 a query for the nearest) cost more rows than its tighter bound
//    saved: on the Bandai volume set (transition) every block of the two
//    nearest visited 5.45% of the rows, their 2 least blocks 4.38%.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "cluster_bound.glsl"
#include "cluster_blocks.glsl"

// Of the blocks of the seed clusters (kNone past the last), the
// kSeedBlocks of least (bound key, block) whose key is <= upper, listed in
// the query's row of `listed`; returns how many. At most the seed clusters'
// block count iterations.
uint least_blocks(uint local_query, uint seeds[kSeedClusters], uint upper, vec4 q[DV], float w[CHANNELS]) {
  uint keys[kSeedBlocks];
  uint blocks[kSeedBlocks];
  [[unroll]] for (uint j = 0u; j < kSeedBlocks; ++j) {
    keys[j] = kSkip;
    blocks[j] = kNone;
  }
  [[unroll]] for (uint s = 0u; s < kSeedClusters; ++s) {
    const uint first = seeds[s] == kNone ? 0u : texelFetch(cluster_info, int(seeds[s] * 3u)).w;
    const uint end = seeds[s] == kNone ? 0u : texelFetch(cluster_info, int(seeds[s] * 3u + 2u)).z;
    for (uint b = first; b < end; ++b) {
      uint block = b;
      uint key = block_key(block, q, w);
      if (key == kSkip || key > upper) continue;
      // Insertion into the sorted list, branch-free: each place keeps the
      // lesser of its pair and the carried one, and carries the other.
      [[unroll]] for (uint j = 0u; j < kSeedBlocks; ++j) {
        const bool less = blocks[j] == kNone || key < keys[j] || (key == keys[j] && block < blocks[j]);
        const uint carried_key = less ? keys[j] : key;
        const uint carried_block = less ? blocks[j] : block;
        keys[j] = less ? key : keys[j];
        blocks[j] = less ? block : blocks[j];
        key = carried_key;
        block = carried_block;
      }
    }
  }
  const uint row = local_query * pc.block_count;
  uint count = 0u;
  [[unroll]] for (uint j = 0u; j < kSeedBlocks; ++j) {
    if (blocks[j] != kNone) listed[row + count++] = blocks[j];
  }
  return count;
}

// Query `base`'s (bound key, centroid distance key) of cluster c, through
// the texel view (cluster_layout.glsl).
uvec2 read_keys(uint base, uint c) { return texelFetch(bound_key_texels, int(base + c)).xy; }

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;
  const uint query = pc.query_base + local_query;
  const uint base = local_query * pc.cluster_count;
  const uint clusters = pc.cluster_count;

  // nprobe mode: the probed clusters are those of distance key < threshold,
  // and the first `at_threshold` (by ascending id) of those at it. Every
  // eligible cluster is probed while there are at most nprobe.
  bool probe_all = true;
  uint threshold = 0u;
  uint at_threshold = 0u;
  if (pc.nprobe != 0u) {
    uint eligible = 0u;
    for (uint c = 0u; c < clusters; ++c) eligible += read_keys(base, c).x != kSkip ? 1u : 0u;
    if (eligible > pc.nprobe) {
      probe_all = false;
      // The least T with count(distance key <= T) >= nprobe (ineligible
      // clusters have distance key kSkip, above every T tried).
      uint lo = 0u;
      uint hi = kSkip - 1u;
      for (uint step = 0u; step < 32u && lo < hi; ++step) {
        const uint mid = lo + ((hi - lo) >> 1u);
        uint n = 0u;
        for (uint c = 0u; c < clusters; ++c) n += read_keys(base, c).y <= mid ? 1u : 0u;
        if (n >= pc.nprobe) {
          hi = mid;
        } else {
          lo = mid + 1u;
        }
      }
      uint below = 0u;
      for (uint c = 0u; c < clusters; ++c) below += read_keys(base, c).y < lo ? 1u : 0u;
      threshold = lo;
      at_threshold = pc.nprobe - below;
    }
  }

  // The kSeedClusters eligible (and probed) clusters of least (centroid
  // distance, id), the first the seed; kNone past the eligible ones. In
  // nprobe mode the same loop marks the clusters not probed kSkip for the
  // merge (this pass reads the keys through the texel view, which need not
  // see its own writes, so it never reads them back).
  uint seeds[kSeedClusters];
  uint seed_distances[kSeedClusters];
  [[unroll]] for (uint j = 0u; j < kSeedClusters; ++j) {
    seeds[j] = kNone;
    seed_distances[j] = kSkip;
  }
  for (uint c = 0u; c < clusters; ++c) {
    const uvec2 keys = read_keys(base, c);
    if (keys.x == kSkip) continue;
    uint cluster = c;
    uint distance = keys.y;
    if (!probe_all) {
      bool probed = distance < threshold;
      if (distance == threshold && at_threshold > 0u) {
        probed = true;
        --at_threshold;
      }
      if (!probed) {
        bound_keys[base + c].x = kSkip;
        continue;
      }
    }
    // Insertion as in least_blocks; ascending ids keep the lower one first on ties.
    [[unroll]] for (uint j = 0u; j < kSeedClusters; ++j) {
      const bool less = seeds[j] == kNone || distance < seed_distances[j];
      const uint carried_distance = less ? seed_distances[j] : distance;
      const uint carried_cluster = less ? seeds[j] : cluster;
      seed_distances[j] = less ? distance : seed_distances[j];
      seeds[j] = less ? cluster : seeds[j];
      distance = carried_distance;
      cluster = carried_cluster;
    }
  }

  vec4 q[DV];
  float w[CHANNELS];
  load_query(query, q, w);
  const uvec2 continuing = continuing_pair(query, q, w);
  uvec2 items = uvec2(0u, 0u);
  if (seeds[0] != kNone) {
    const uint upper = pc.k == 1u && continuing.y != kNone ? continuing.x : kSkip;
    items = move_listed(0u, local_query, least_blocks(local_query, seeds, upper, q, w));
  }
  states[query].continuing_pair = continuing;
  states[query].items0 = items;
}
