// Cluster search, pass 4 (twice per chunk): one invocation per query merges
// the continuing frame's pair and the per-lane best pairs of its work items
// into the query's best K, in the strict (cost, frame) order.
//  round 0: cluster_select's items; the k-th best key is the upper bound
//           of round 1 (kSkip while fewer than k were found); lists, of the
//           clusters whose bound key is <= it, the blocks not scanned in
//           round 0 whose own bound key is <= it (block-level culling: a
//           block's box is much tighter than its cluster's) for scan
//           round 1.
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

// Lists, in the query's row of `listed`, the blocks whose bound key is <=
// upper (strictly greater cannot win; equal may still win on a lower frame
// id) of the clusters whose bound key is <= upper, except round 0's
// (items0); returns how many. Two loops: the clusters that can win go to the
// row's tail (the i-th at block_count - 1 - i), then one flat loop takes
// them from the last and tests their blocks, each iteration either moving
// to the next cluster or testing one block. The lanes of a SIMD group
// (different queries) so run about max(clusters that can win + their
// blocks) iterations, where a loop over the clusters with an inner loop
// over their blocks ran the union of the lanes' blocks (the largest cost of
// small blocks on lavapipe). Blocks are listed at the row's front: before
// the m-th cluster taken is tested, at most (its blocks and the earlier
// ones') <= block_count - (clusters left) entries are written, so the
// front never reaches a tail entry still to be read. The order of the
// items does not change the results (the merges insert pairs in a strict
// total order). At most cluster_count, then cluster_count + block_count
// iterations.
uint list_other_blocks(uint local_query, uvec2 items0, uint upper, vec4 q[DV], float w[CHANNELS]) {
  // Round 0's blocks (at most kSeedBlocks), kNone where fewer.
  uint seed_blocks[kSeedBlocks];
  [[unroll]] for (uint j = 0u; j < kSeedBlocks; ++j) {
    seed_blocks[j] = j < items0.y ? work_items[items0.x + j].y : kNone;
  }
  const uint key_base = local_query * pc.cluster_count;
  const uint row = local_query * pc.block_count;
  uint tail = pc.block_count;
  for (uint c = 0u; c < pc.cluster_count; ++c) {
    const uint key = texelFetch(bound_key_texels, int(key_base + c)).x;
    if (key != kSkip && key <= upper) {
      --tail;
      listed[row + tail] = c;
    }
  }
  uint count = 0u;
  uint b = 0u;
  uint end = 0u;
  while (b < end || tail < pc.block_count) {
    if (b < end) {
      bool scanned = false;
      [[unroll]] for (uint j = 0u; j < kSeedBlocks; ++j) {
        const bool in_round_0 = b == seed_blocks[j];  // a named bool: no branch for ||
        scanned = scanned || in_round_0;
      }
      const uint key = scanned ? kSkip : block_key(b, q, w);
      if (key != kSkip && key <= upper) {
        listed[row + count] = b;
        ++count;
      }
      ++b;
    } else {
      const uint c = listed[row + tail];
      ++tail;
      b = texelFetch(cluster_info, int(c * 3u)).w;
      end = texelFetch(cluster_info, int(c * 3u + 2u)).z;
    }
  }
  return count;
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
    states[query].items1 = move_listed(1u, local_query, list_other_blocks(local_query, state.items0, upper, q, w));
    return;
  }

  rows += merge_items(best, state.items1);
  rows += state.continuing_pair.y != kNone ? 1u : 0u;
  [[unroll]] for (uint j = 0; j < K; ++j) results[query * K + j] = best[j];
  states[query].rows = rows;
}
