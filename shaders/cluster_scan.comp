// Cluster search, pass 3 (twice per chunk, indirect): one invocation per
// tile, a member block and up to pc.tile work items (query, block) that
// visit it (cluster_sort.comp sorted the round's items by block), evaluates
// the block's rows for the tile's queries held in registers and writes each
// item's best K (key, frame) pairs at the item's place in block_pairs.
// Batch by block: the row's texel fetches (features, metadata, cost terms)
// are shared by the tile, as in the brute-force scan; one invocation per
// (query, block) was gather-bound (about 7M rows/s on lavapipe). Lanes of a
// SIMD group work on different blocks (splitting a block over 8 lanes and
// merging through shared memory was 1.35x slower on lavapipe).
//  round 0: the kSeedBlocks blocks listed by cluster_select;
//  round 1: the blocks, of every other cluster, whose bound key is <= the
//           k-th best key after round 0 (listed by cluster_merge round 0).
// Rows are read in cluster order (member_rows: a block's rows are
// contiguous) and evaluated with the brute-force scan's arithmetic and
// candidate rules (search_cost.glsl); the continuing frame is skipped
// (cluster_select evaluated it with its bias). The row loop runs at most
// rows_per_block iterations (llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

layout(constant_id = 3) const uint T = 1;  // work items per tile (= pc.tile)

#define kInfinity uintBitsToFloat(0x7F800000u)

// The block of tile `tile`: the last block whose first tile is <= it (a
// block with no items has the same first tile as the next one).
uint tile_block(uint tile) {
  uint lo = 0u;
  uint hi = pc.block_count - 1u;
  while (lo < hi) {
    const uint mid = (lo + hi + 1u) >> 1u;
    if (block_sort[sort_tile_start(mid)] <= tile) {
      lo = mid;
    } else {
      hi = mid - 1u;
    }
  }
  return lo;
}

// Evaluates tile `tile` (main: one per invocation, more with a grid stride
// past kMaxIndirectGroups workgroups).
void scan_tile(uint tile) {
  const uint round_base = pc.round == 0u ? 0u : scan_dispatch[0].w;
  const uint block = tile_block(tile);
  const uint first = block_sort[sort_item_start(block)] + (tile - block_sort[sort_tile_start(block)]) * T;
  const uint count = min(T, block_sort[sort_item_start(block + 1u)] - first);
  const uvec4 info = texelFetch(block_info, int(block * 2u));

  // Slots past the tile's count repeat its last item (not written).
  uint item[T];
  vec4 q[T][DV];
  float w[T][CHANNELS];
  uvec4 tags[T];     // tag_rule(): (mask lo, mask hi, wanted lo, wanted hi)
  uvec4 skipped[T];  // QueryGpu's skipped frames (the continuing frame and its window), or every frame
  // K = 1: the running best; a frame of kNone is an empty slot. Rows run in
  // descending frame order (a block's members ascend), so `cost <= best`
  // keeps the lowest frame among ties, accepts an infinite cost into an
  // empty slot and rejects NaN.
  float best_cost[T];
  uint best_frame[T];
  // K > 1: the best K, sorted, and the cost of the last (+inf while empty).
  uvec2 best[T][K];
  float worst[T];
  [[unroll]] for (uint t = 0; t < T; ++t) {
    item[t] = block_sort[sort_sorted(round_base + first + min(t, count - 1u))];
    const uint query = pc.query_base + work_items[item[t]].x;
    load_query(query, q[t], w[t]);
    const QueryGpu p = query_params_of(query);
    bool rejects_all;
    tags[t] = tag_rule(p, rejects_all);
    // Frame r is skipped when r - 0 <= kNone: every frame.
    const uvec4 ranges = uvec4(p.skip_first_a, p.skip_span_a, p.skip_first_b, p.skip_span_b);
    skipped[t] = rejects_all ? uvec4(0u, kNone, 0u, kNone) : ranges;
    best_cost[t] = kInfinity;
    best_frame[t] = kNone;
    clear_pairs(best[t]);
    worst[t] = kInfinity;
  }

  for (uint m = info.z; m > info.y;) {
    --m;
    const uvec4 meta = texelFetch(member_meta, int(m));  // (frame, flags, tags lo, tags hi)
    const uint r = meta.x;
    // The candidate rules as in the brute force, branch-free: a flagged row
    // gets a NaN bias (with unit cost terms, which add no bias, it is
    // rejected instead), the tags and the exclusion window are integer
    // operations on named bools (glslang compiles a short-circuit operator
    // whose right side is an expression into a branch).
    const bool never = (meta.y & kNeverCandidate) != 0u;
    const bool never_unit = UNIT_COST_TERMS != 0u && never;
    vec2 scale_bias = vec2(1.0, 0.0);
    if (UNIT_COST_TERMS == 0u) scale_bias = texelFetch(member_cost, int(m)).xy;
    scale_bias.y = mix(scale_bias.y, uintBitsToFloat(0x7FC00000u), UNIT_COST_TERMS == 0u && never);
    vec4 x[DV];
    [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(member_rows, int(m * DV + v));
    // Two queries at a time (row_totals2()), the last alone when T is odd.
    [[unroll]] for (uint pair = 0; pair < T; pair += 2u) {
      float totals[2];
      if (pair + 1u < T) {
        row_totals2(x, q[pair], w[pair], q[pair + 1u], w[pair + 1u], totals[0], totals[1]);
      } else {
        totals[0] = row_total(x, q[pair], w[pair]);
      }
      // Constant bounds, so the loop unrolls (llvmpipe's loop limit).
      [[unroll]] for (uint i = 0u; i < 2u; ++i) {
        const uint t = pair + i;
        if (t >= T) break;
        const float cost = UNIT_COST_TERMS != 0u ? totals[i] : scaled_cost(totals[i], scale_bias);
        const bool tag_rejected_lo = TAG_WORDS >= 1u && (meta.z & tags[t].x) != tags[t].z;
        const bool tag_rejected_hi = TAG_WORDS >= 2u && (meta.w & tags[t].y) != tags[t].w;
        const bool skipped_a = r - skipped[t].x <= skipped[t].y;
        const bool skipped_b = r - skipped[t].z <= skipped[t].w;
        const bool rejected = tag_rejected_lo || tag_rejected_hi || skipped_a || skipped_b || never_unit;
        keep_row(best_cost[t], best_frame[t], best[t], worst[t], cost, r, rejected, true);
      }
    }
  }

  [[unroll]] for (uint t = 0; t < T; ++t) {
    if (t >= count) break;
    if (K == 1u) {
      block_pairs[item[t]] =
          best_frame[t] == kNone ? uvec2(kNone, kNone) : uvec2(orderable_bits(best_cost[t]), best_frame[t]);
    } else {
      [[unroll]] for (uint j = 0; j < K; ++j) block_pairs[item[t] * K + j] = best[t][j];
    }
  }
}

void main() {
  const uint tiles = scan_dispatch[kTileDispatchEntry + pc.round].w;
  const uint stride = gl_NumWorkGroups.x * kItemsPerScanGroup;
  for (uint tile = gl_GlobalInvocationID.x; tile < tiles; tile += stride) scan_tile(tile);
}
