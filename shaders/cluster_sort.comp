// Cluster search, between listing and scanning (per round, three steps, one
// pipeline each): a counting sort of the round's work items by block, so
// that cluster_scan evaluates each block once for a tile of up to pc.tile
// queries that visit it (batch by block: a row is loaded once per tile,
// where a scan per (query, block) loaded it once per query).
// Per-item steps loop with a grid stride past kMaxIndirectGroups groups.
//  STEP 0 (per item, indirect on the round's item count): the item's rank
//         among its block's items (an atomic counter per block);
//  STEP 1 (one invocation): exclusive prefix sums over the blocks of the
//         item counts and of the tile counts; writes the tiled scan's
//         indirect dispatch (at most block_count iterations, within
//         llvmpipe's loop limit since blocks <= 60,000 / 3);
//  STEP 2 (per item): the item at its sorted position.
// The order of items within a block does not matter: every item's pairs
// are written at its own place in block_pairs, so the merges (and the
// results) are the same whatever the tiling.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"

layout(constant_id = 11) const uint STEP = 0;

void main() {
  const uint round = pc.round;
  const uint round_base = round == 0u ? 0u : scan_dispatch[0].w;
  if (STEP == 1u) {
    if (gl_GlobalInvocationID.x != 0u) return;
    uint items = 0u;
    uint tiles = 0u;
    for (uint b = 0u; b < pc.block_count; ++b) {
      block_sort[sort_item_start(b)] = items;
      block_sort[sort_tile_start(b)] = tiles;
      const uint count = block_sort[sort_fill(round, b)];
      items += count;
      tiles += (count + pc.tile - 1u) / pc.tile;
    }
    block_sort[sort_item_start(pc.block_count)] = items;
    block_sort[sort_tile_start(pc.block_count)] = tiles;
    const uint groups = min((tiles + kItemsPerScanGroup - 1u) / kItemsPerScanGroup, kMaxIndirectGroups);
    scan_dispatch[kTileDispatchEntry + round] = uvec4(groups, 1u, 1u, tiles);
    return;
  }
  const uint items = scan_dispatch[round].w;
  const uint stride = gl_NumWorkGroups.x * kItemsPerScanGroup;
  for (uint local_item = gl_GlobalInvocationID.x; local_item < items; local_item += stride) {
    const uint item = round_base + local_item;
    const uint block = work_items[item].y;
    if (STEP == 0u) {
      block_sort[sort_rank(item)] = atomicAdd(block_sort[sort_fill(round, block)], 1u);
    } else {
      const uint position = block_sort[sort_item_start(block)] + block_sort[sort_rank(item)];
      block_sort[sort_sorted(round_base + position)] = item;
    }
  }
}
