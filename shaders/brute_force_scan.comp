// Exact brute-force search, pass 1 of 2: every invocation scans one block of
// rows for a tile of T queries held in registers, and writes each query's
// best K (cost, frame) pairs of that block to the scratch buffer; pass 2
// (topk_merge.comp) merges the blocks.
//
// Why this shape (shared/LAVAPIPE.md): query tiles in registers beat shared
// memory 3-5x on lavapipe; rows are read as RGBA32F texels (vectorized
// gathers); the row loop runs at most rows_per_invocation (<= 32k)
// iterations and every inner loop is unrolled, because llvmpipe silently
// stops loops after 65,535 iterations. The candidate rules are checked only
// for pairs that would enter the best K, which is rare after the first rows.
//
// Costs follow the reference order exactly (runtime/src/search.cpp):
// per channel a sum of squared differences in dim order from 0.0, then
// total += w_c * sum in channel order, cost = multiplier * total + bias,
// + continuing_bias last; `precise` keeps real GPUs from fusing.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "search_layout.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint DV = 1;        // padded dims / 4
layout(constant_id = 2) const uint DIMS = 1;      // real dims (<= 128)
layout(constant_id = 3) const uint T = 1;         // queries per tile
layout(constant_id = 4) const uint K = 1;         // best pairs kept per query
layout(constant_id = 5) const uint CHANNELS = 1;  // non-empty channels
// Bit d set: dimension d is the last of its channel.
layout(constant_id = 6) const uint END_MASK_0 = 0u;
layout(constant_id = 7) const uint END_MASK_1 = 0u;
layout(constant_id = 8) const uint END_MASK_2 = 0u;
layout(constant_id = 9) const uint END_MASK_3 = 0u;

// Constant-folds once d is a constant (all callers are unrolled loops).
bool ends_channel(uint d) {
  uint word = d < 32u ? END_MASK_0 : d < 64u ? END_MASK_1 : d < 96u ? END_MASK_2 : END_MASK_3;
  return ((word >> (d & 31u)) & 1u) != 0u;
}

// The query of tile slot `local`; slots past the chunk's end repeat its
// last query (their results are not written).
uint query_index(uint local) { return pc.query_base + min(local, pc.query_count - 1u); }

// The search semantics' candidate rule (mmvk::is_candidate).
// meta: (flags, tags low, tags high, clip) of row r.
bool is_candidate(uint r, uvec4 meta, bool continuing, QueryGpu p) {
  if ((meta.x & (kFrameDoNotUse | kFrameEdgeExcluded)) != 0u) return false;
  if ((meta.x & kFrameBlockTransition) != 0u && !continuing) return false;
  if ((meta.y & p.require_lo) != p.require_lo || (meta.z & p.require_hi) != p.require_hi) return false;
  if ((meta.y & p.exclude_lo) != 0u || (meta.z & p.exclude_hi) != 0u) return false;
  if (meta.w == p.window_clip && !continuing) {
    const uint a = r - p.clip_first;
    const uint b = p.continuing_frame - p.clip_first;
    uint distance = a > b ? a - b : b - a;
    if (p.clip_loop != 0u) distance = min(distance, p.clip_count - distance);
    if (distance <= p.exclusion_window) return false;
  }
  return true;
}

void main() {
  const uint block = gl_GlobalInvocationID.x;
  if (block >= pc.block_count) return;
  const uint tile_first = gl_WorkGroupID.y * T;

  vec4 q[T][DV];
  float w[T][CHANNELS];
  QueryGpu p[T];
  uvec2 best[T][K];
  float worst[T];  // cost of best[t][K - 1], +inf while that slot is empty
  [[unroll]] for (uint t = 0; t < T; ++t) {
    const uint query = query_index(tile_first + t);
    [[unroll]] for (uint v = 0; v < DV; ++v) q[t][v] = query_features[query * DV + v];
    [[unroll]] for (uint c = 0; c < CHANNELS; ++c) w[t][c] = query_weights[query * CHANNELS + c];
    // In registers: reading a storage buffer inside the row loop, even in a
    // rarely taken branch, made the kernel 2x slower on lavapipe.
    p[t] = query_params[query];
    [[unroll]] for (uint j = 0; j < K; ++j) best[t][j] = uvec2(kNone, kNone);
    worst[t] = uintBitsToFloat(0x7F800000u);
  }

  const uint row_begin = block * pc.rows_per_invocation;
  const uint row_end = min(row_begin + pc.rows_per_invocation, pc.frame_count);
  for (uint r = row_begin; r < row_end; ++r) {
    const uvec4 meta = texelFetch(frame_meta, int(r));
    const vec2 scale_bias = texelFetch(frame_cost, int(r)).xy;
    vec4 x[DV];
    [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(features, int(r * DV + v));

    [[unroll]] for (uint t = 0; t < T; ++t) {
      precise float total = 0.0;
      precise float channel_sum = 0.0;
      uint c = 0u;
      [[unroll]] for (uint d = 0; d < DIMS; ++d) {
        precise float diff = x[d >> 2u][d & 3u] - q[t][d >> 2u][d & 3u];
        channel_sum = channel_sum + diff * diff;
        if (ends_channel(d)) {
          total = total + w[t][c] * channel_sum;
          channel_sum = 0.0;
          ++c;
        }
      }
      precise float cost = scale_bias.x * total + scale_bias.y;
      const bool continuing = r == p[t].continuing_frame;
      if (continuing) cost = cost + p[t].continuing_bias;

      // One float compare on the hot path (NaN and ties pass it); the exact
      // (cost, frame) order and the candidate rules run only for a pair that
      // may enter the best K, which is rare once good rows were seen.
      if (!(cost > worst[t])) {
        const uvec2 candidate = uvec2(orderable_bits(cost), r);
        if (pair_less(candidate, best[t][K - 1u]) && !isnan(cost) && is_candidate(r, meta, continuing, p[t])) {
          best[t][K - 1u] = candidate;
          [[unroll]] for (uint j = K - 1u; j > 0u; --j) {
            if (pair_less(best[t][j], best[t][j - 1u])) {
              const uvec2 swap = best[t][j];
              best[t][j] = best[t][j - 1u];
              best[t][j - 1u] = swap;
            }
          }
          worst[t] = best[t][K - 1u].y == kNone ? uintBitsToFloat(0x7F800000u) : cost_of_key(best[t][K - 1u].x);
        }
      }
    }
  }

  [[unroll]] for (uint t = 0; t < T; ++t) {
    const uint local_query = tile_first + t;
    if (local_query >= pc.query_count) break;
    const uint base = (local_query * pc.block_count + block) * K;
    [[unroll]] for (uint j = 0; j < K; ++j) scratch[base + j] = best[t][j];
  }
}
