// The work lists of the cluster scans and the block culling, shared by
// cluster_select (round 0) and cluster_merge (round 1). Needs
// kernel_shape.glsl, cluster_layout.glsl, search_cost.glsl and
// cluster_bound.glsl.
#ifndef MMVK_CLUSTER_BLOCKS_GLSL
#define MMVK_CLUSTER_BLOCKS_GLSL

// Only the visited blocks are dispatched (a grid over every (block, query)
// spent most of its time on pruned invocations: 435 of 500 ms on 22k
// frames). A query lists its blocks of a round in its own row of `listed`,
// then moves them to consecutive work items reserved with one atomic (so
// the merge finds them as a range); returns (first item, count), the first
// counted from item 0 of round 0. The group count is
// min(ceil(items / kItemsPerScanGroup), kMaxIndirectGroups), raised by each
// reservation's share.
uvec2 move_listed(uint round, uint local_query, uint count) {
  if (count == 0u) return uvec2(0u, 0u);
  const uint first = atomicAdd(scan_dispatch[round].w, count);
  const uint g = kItemsPerScanGroup;
  const uint groups = (first + count + g - 1u) / g - (first + g - 1u) / g;
  if (groups != 0u) {
    // Adds then clamps: whatever the interleaving, x ends at
    // min(total groups, kMaxIndirectGroups).
    atomicAdd(scan_dispatch[round].x, groups);
    atomicMin(scan_dispatch[round].x, kMaxIndirectGroups);
  }
  const uint base = round == 0u ? first : scan_dispatch[0].w + first;
  const uint row = local_query * pc.block_count;
  for (uint i = 0u; i < count; ++i) work_items[base + i] = uvec2(local_query, listed[row + i]);
  return uvec2(base, count);
}

// The bound key of member block b for a query (q, w): its box bound, or
// kSkip when every member is a non-candidate (the continuing frame, the
// only exception, is evaluated apart).
uint block_key(uint b, vec4 q[DV], float w[CHANNELS]) {
  const uvec4 info = texelFetch(block_info, int(b * 2u));
  if ((info.w & kNeverCandidate) != 0u) return kSkip;
  vec4 lo[DV];
  vec4 hi[DV];
  [[unroll]] for (uint v = 0; v < DV; ++v) {
    lo[v] = texelFetch(block_vectors, int((b * 2u) * DV + v));
    hi[v] = texelFetch(block_vectors, int((b * 2u + 1u) * DV + v));
  }
  return bound_key(box_total(q, w, lo, hi), texelFetch(block_info, int(b * 2u + 1u)).xy);
}

#endif
