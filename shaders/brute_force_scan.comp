// Exact brute-force search, pass 1 of 2: every invocation scans one block of
// rows for a tile of T queries held in registers, and writes each query's
// best K (cost, frame) pairs of that block to the scratch buffer; pass 2
// (topk_merge.comp) merges the blocks and adds each query's continuing
// frame, which this pass skips.
//
// A workgroup scans rows_per_invocation x WG consecutive rows and its lanes
// take them in turn (lane l: rows first + l, first + WG + l, ...), so at
// every step the lanes read consecutive rows: with the feature rows
// interleaved by kRowGroup (search_layout.glsl) each texel fetch reads one
// contiguous run, coalesced on a GPU and a single prefetchable stream on
// lavapipe. With a block of consecutive rows per lane, the 8 lanes read 8
// streams a block apart, and a third of lavapipe's time went to the stalls
// of those loads (perf, Bandai volume 417k). Workgroups are dispatched
// tiles first (x = tile, y = row group), so the tiles that read the same
// rows run one after another, while the rows are still in the caches.
//
// Why this shape (shared/LAVAPIPE.md): query tiles in registers beat shared
// memory 3-5x on lavapipe; rows are read as RGBA32F texels (vectorized
// gathers); the row loop runs at most rows_per_invocation (<= 32k)
// iterations and every inner loop is unrolled, because llvmpipe silently
// stops loops after 65,535 iterations. The cost arithmetic is
// search_cost.glsl's (the reference's order, `precise`).
//
// The hot path is branch-free: llvmpipe runs both sides of every `if` under
// a lane mask, so a rarely taken branch costs as much as an always taken
// one. Per (row, query) it evaluates the cost, the tag rules (integer
// operations, none on a database without tags) and, for K = 1, two
// selects; the exclusion window's tests run only in the band of rows some
// query of the tile skips.
// What makes that possible:
// - The continuing frame is the only row whose cost has an extra term
//   (continuing_bias) and the only one exempt from block transitions and
//   the exclusion window; it is excluded here and evaluated once per query
//   by the merge pass.
// - Per-row flags exclude a row for every query alike, so the scan visits
//   only the frames of scan_frames, the rows no flag excludes (11% fewer on
//   the Bandai volume set), as the CPU tile store does.
// - In this mode the feature matrix holds those rows first, in scan order
//   (runtime/vulkan/src/scan_rows.hpp): the loop reads row j's features and
//   terms at j and never fetches its frame (that fetch, and the features'
//   wait for it, were 10% of the time); a block looks up the frames of
//   only the rows it keeps, at its end.
// - The exclusion window is at most two row ranges per query (a looping
//   clip wraps), mapped to scan rows by the host (QueryGpu). The steps of
//   an invocation that hold some query's skipped rows form one band, scanned
//   by a loop of its own with the tests; the main loop skips the band and
//   tests nothing (Bandai volume set, B = 1,024: 5% faster with lavapipe's
//   code for an AVX2 host, 4% with its AVX-512 code).
// - Rows are scanned in descending order (their frames ascend with them),
//   so `cost <= best` keeps the lowest frame among equal costs (the
//   reference's order), accepts an infinite cost into an empty slot and
//   rejects NaN, in one comparison (keep_row(), top_k.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "search_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

layout(constant_id = 3) const uint T = 1;  // queries per tile

#define kInfinity uintBitsToFloat(0x7F800000u)

// The query of tile slot `local`; slots past the chunk's end repeat its
// last query (their results are not written).
uint query_index(uint local) { return pc.query_base + min(local, pc.query_count - 1u); }

// Widens the steps [lo, hi) to hold those of this lane's rows (first + step
// x j, j < steps) that lie in the skipped range [a, a + span] (a = kNone:
// none).
void widen_band(uint a, uint span, uint first, uint step, uint steps, inout uint lo, inout uint hi) {
  if (a == kNone || a + span < first) return;
  const uint j_first = a <= first ? 0u : (a - first + step - 1u) / step;
  const uint j_end = min(steps, (a + span - first) / step + 1u);
  if (j_first >= j_end) return;
  lo = min(lo, j_first);
  hi = max(hi, j_end);
}

// Scan row `row`'s terms (tags lo, tags hi, multiplier bits, bias bits;
// not read, zeros, when no tag and no cost term can matter: a database
// without tags, multipliers or biases) and features.
void load_row(uint row, out uvec4 terms, out vec4 x[DV]) {
  terms = uvec4(0u);
  if (TAG_WORDS != 0u || UNIT_COST_TERMS == 0u) terms = texelFetch(scan_terms, int(row));
  [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(features, feature_texel(row, v));
}

// The frame of scan row `row`.
uint frame_of_row(uint row) { return texelFetch(scan_frames, int(row)).x; }

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint block = gl_WorkGroupID.y * gl_WorkGroupSize.x + lane;
  if (block >= pc.block_count) return;
  const uint tile_first = gl_WorkGroupID.x * T;

  vec4 q[T][DV];
  float w[T][CHANNELS];
  // In registers: reading a storage buffer inside the row loop made the
  // kernel 2x slower on lavapipe.
  uvec4 tags[T];     // tag_rule(): (mask lo, mask hi, wanted lo, wanted hi)
  uvec4 skipped[T];  // QueryGpu's skipped scan rows: (first, last - first) twice
  bool rejects_all[T];  // tag_rule(): no row can pass (its result is written empty)
  // K = 1: the running best; a row of kNone is an empty slot.
  float best_cost[T];
  uint best_row[T];
  // K > 1: the best K as (orderable cost bits, scan row), sorted, and the
  // cost of the last one (+inf while it is empty). Scan rows ascend with
  // their frames, so the order is the frames' order.
  uvec2 best[T][K];
  float worst[T];
  [[unroll]] for (uint t = 0; t < T; ++t) {
    const uint query = query_index(tile_first + t);
    load_query(query, q[t], w[t]);
    const QueryGpu p = query_params_of(query);
    tags[t] = tag_rule(p, rejects_all[t]);
    skipped[t] = uvec4(p.skip_first_a, p.skip_span_a, p.skip_first_b, p.skip_span_b);
    best_cost[t] = kInfinity;
    best_row[t] = kNone;
    clear_pairs(best[t]);
    worst[t] = kInfinity;
  }

  // This lane's rows of scan_frames: first + step x j for j < steps,
  // scanned downwards (their frames ascend with them).
  const uint step = gl_WorkGroupSize.x;
  const uint first = gl_WorkGroupID.y * step * pc.rows_per_invocation + lane;
  const uint steps = first >= pc.scan_rows ? 0u : min(pc.rows_per_invocation, (pc.scan_rows - first + step - 1u) / step);
  // The skipped rows (each query's continuing frame and exclusion window)
  // are a few short ranges: the steps j in [band_lo, band_hi) hold every
  // one of this lane's rows that some query of the tile skips. The main
  // loop scans the other steps with no skip tests (they were about a tenth
  // of its work), downwards, so `cost <= best` keeps the lowest row among
  // equal costs; the band loop scans the band with the tests, in any order,
  // with that tie rule spelled out.
  uint band_lo = steps;
  uint band_hi = 0u;
  [[unroll]] for (uint t = 0; t < T; ++t) {
    widen_band(skipped[t].x, skipped[t].y, first, step, steps, band_lo, band_hi);
    widen_band(skipped[t].z, skipped[t].w, first, step, steps, band_lo, band_hi);
  }
  if (band_lo >= band_hi) {
    band_lo = 0u;
    band_hi = 0u;
  }
  const uint band = band_hi - band_lo;
  for (uint n = steps - band; n > 0u;) {
    --n;
    const uint row = first + (n < band_lo ? n : n + band) * step;
    uvec4 terms;
    vec4 x[DV];
    load_row(row, terms, x);
    const vec2 scale_bias = uintBitsToFloat(terms.zw);

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
        // The candidate rules as integer operations. Every operand of || and
        // && is a named bool: glslang compiles a short-circuit operator whose
        // right side is an expression into a branch.
        const bool tag_rejected_lo = TAG_WORDS >= 1u && (terms.x & tags[t].x) != tags[t].z;
        const bool tag_rejected_hi = TAG_WORDS >= 2u && (terms.y & tags[t].y) != tags[t].w;
        const bool rejected = tag_rejected_lo || tag_rejected_hi;
        keep_row(best_cost[t], best_row[t], best[t], worst[t], cost, row, rejected, true);
      }
    }
  }

  // The band, with the skip tests (its loop over the tile is unrolled too:
  // indexing the tile's arrays by a loop variable moved them to memory for
  // the whole kernel, 20% slower).
  for (uint j = band_lo; j < band_hi; ++j) {
    const uint row = first + j * step;
    uvec4 terms;
    vec4 x[DV];
    load_row(row, terms, x);
    const vec2 scale_bias = uintBitsToFloat(terms.zw);
    [[unroll]] for (uint t = 0; t < T; ++t) {
      const float total = row_total(x, q[t], w[t]);
      const float cost = UNIT_COST_TERMS != 0u ? total : scaled_cost(total, scale_bias);
      const bool tag_rejected_lo = TAG_WORDS >= 1u && (terms.x & tags[t].x) != tags[t].z;
      const bool tag_rejected_hi = TAG_WORDS >= 2u && (terms.y & tags[t].y) != tags[t].w;
      const bool skipped_a = row - skipped[t].x <= skipped[t].y;
      const bool skipped_b = row - skipped[t].z <= skipped[t].w;
      const bool rejected = tag_rejected_lo || tag_rejected_hi || skipped_a || skipped_b;
      keep_row(best_cost[t], best_row[t], best[t], worst[t], cost, row, rejected, false);
    }
  }

  [[unroll]] for (uint t = 0; t < T; ++t) {
    const uint local_query = tile_first + t;
    if (local_query >= pc.query_count) break;
    const uint base = (local_query * pc.block_count + block) * K;
    if (rejects_all[t]) {
      [[unroll]] for (uint j = 0; j < K; ++j) scratch[base + j] = uvec2(kNone, kNone);
    } else if (K == 1u) {
      const bool empty = best_row[t] == kNone;
      scratch[base] = empty ? uvec2(kNone, kNone) : uvec2(orderable_bits(best_cost[t]), frame_of_row(best_row[t]));
    } else {
      [[unroll]] for (uint j = 0; j < K; ++j) {
        scratch[base + j] = best[t][j].y == kNone ? best[t][j] : uvec2(best[t][j].x, frame_of_row(best[t][j].y));
      }
    }
  }
}
