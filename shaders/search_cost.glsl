// The cost and candidate rules of the search semantics (docs/search.md,
// runtime/src/search.cpp), as the cluster kernels evaluate them; the same
// arithmetic as brute_force_scan.comp, so both give the reference's bits.
#ifndef MMVK_SEARCH_COST_GLSL
#define MMVK_SEARCH_COST_GLSL

#include "kernel_shape.glsl"
#include "search_layout.glsl"

// The texel of row r's vec4 v: the rows are interleaved by kRowGroup
// (search_layout.glsl).
int feature_texel(uint r, uint v) { return int(((r / kRowGroup) * DV + v) * kRowGroup + r % kRowGroup); }

// Constant-folds once d is a constant (all callers are unrolled loops).
bool ends_channel(uint d) {
  uint word = d < 32u ? END_MASK_0 : d < 64u ? END_MASK_1 : d < 96u ? END_MASK_2 : END_MASK_3;
  return ((word >> (d & 31u)) & 1u) != 0u;
}

// mmvk::is_candidate. meta: (flags, tags low, tags high, clip) of row r.
bool frame_is_candidate(uint r, uvec4 meta, bool continuing, QueryGpu p) {
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

// Constant-folds once d is a constant, as ends_channel().
bool starts_channel(uint d) { return d == 0u || ends_channel(d - 1u); }

// mmvk::frame_cost without the continuing bias: per channel a sum of
// squared differences in dim order from 0, total += w_c * sum in channel
// order, multiplier * total + bias; `precise` forbids fusing. A channel's
// sum starts at its first square, not at 0 + that square: the same bits (a
// square is never -0.0; NaN stays NaN) and one addition fewer per channel,
// which `precise` keeps the compiler from removing. The total keeps its
// 0 + w_0 x sum: a weight of -0.0 passes validation and would give -0.0.
// row_total() is the weighted sum, row_cost() the whole cost.
float row_total(vec4 x[DV], vec4 q[DV], float w[CHANNELS]) {
  precise float total = 0.0;
  precise float channel_sum = 0.0;
  uint c = 0u;
  [[unroll]] for (uint d = 0; d < DIMS; ++d) {
    precise float diff = x[d >> 2u][d & 3u] - q[d >> 2u][d & 3u];
    if (starts_channel(d)) {
      channel_sum = diff * diff;
    } else {
      channel_sum = channel_sum + diff * diff;
    }
    if (ends_channel(d)) {
      total = total + w[c] * channel_sum;
      ++c;
    }
  }
  return total;
}

// row_total() of two queries, a and b, dim by dim: each of the row's
// values serves both queries before the next, where query by query the
// row's DV vec4s had to stay live across a whole query. Lavapipe's code
// for an AVX2 host has 16 vector registers and reloaded them for every
// query (its brute force ran 6-9% faster paired, bench/RESULTS.md). Each
// query's operations are row_total()'s, in its order.
void row_totals2(vec4 x[DV], vec4 qa[DV], float wa[CHANNELS], vec4 qb[DV], float wb[CHANNELS], out float total_a,
                 out float total_b) {
  precise float ta = 0.0;
  precise float tb = 0.0;
  precise float sa = 0.0;
  precise float sb = 0.0;
  uint c = 0u;
  [[unroll]] for (uint d = 0; d < DIMS; ++d) {
    const float xd = x[d >> 2u][d & 3u];
    precise float da = xd - qa[d >> 2u][d & 3u];
    precise float db = xd - qb[d >> 2u][d & 3u];
    if (starts_channel(d)) {
      sa = da * da;
      sb = db * db;
    } else {
      sa = sa + da * da;
      sb = sb + db * db;
    }
    if (ends_channel(d)) {
      ta = ta + wa[c] * sa;
      tb = tb + wb[c] * sb;
      ++c;
    }
  }
  total_a = ta;
  total_b = tb;
}

// multiplier x total + bias, rounded in that order (row_cost()).
float scaled_cost(float total, vec2 scale_bias) {
  precise float cost = scale_bias.x * total + scale_bias.y;
  return cost;
}

float row_cost(vec4 x[DV], vec4 q[DV], float w[CHANNELS], vec2 scale_bias) {
  return scaled_cost(row_total(x, q, w), scale_bias);
}

// Query p's tag rules as one test per tag word w < TAG_WORDS: a row passes
// when (row tags & mask) == wanted, with mask = require | exclude and
// wanted = require (the scans' one test per word and row). rejects_all:
// no row can pass (a tag both required and excluded, or required in a word
// no frame uses).
uvec4 tag_rule(QueryGpu p, out bool rejects_all) {
  rejects_all = (p.require_lo & p.exclude_lo) != 0u || (p.require_hi & p.exclude_hi) != 0u ||
                (TAG_WORDS < 1u && p.require_lo != 0u) || (TAG_WORDS < 2u && p.require_hi != 0u);
  return uvec4(p.require_lo | p.exclude_lo, p.require_hi | p.exclude_hi, p.require_lo, p.require_hi);
}

// The features (padded like the rows) and channel weights of query `query`.
void load_query(uint query, out vec4 q[DV], out float w[CHANNELS]) {
  [[unroll]] for (uint v = 0; v < DV; ++v) q[v] = query_feature(query, v);
  [[unroll]] for (uint c = 0; c < CHANNELS; ++c) w[c] = query_weight(query, c);
}

// The (cost, frame) pair of query `query`'s continuing frame (q, w: the
// query's features and weights, load_query()), continuing_multiplier and
// continuing_bias included, or (kNone, kNone) when it has none
// (validate_search keeps it below the frame count otherwise), it is not a
// candidate or its cost is NaN. The scans skip this frame: it is the only row with an extra cost term
// and exemptions from the rules, so it is evaluated once per query.
uvec2 continuing_pair(uint query, vec4 q[DV], float w[CHANNELS]) {
  const QueryGpu p = query_params_of(query);
  const uint frame = p.continuing_frame;
  if (frame == kNone) return uvec2(kNone, kNone);
  if (!frame_is_candidate(frame, texelFetch(frame_meta, int(frame)), true, p)) return uvec2(kNone, kNone);
  vec4 x[DV];
  [[unroll]] for (uint v = 0; v < DV; ++v) x[v] = texelFetch(features, feature_texel(p.continuing_row, v));
  // mmvk::frame_cost's order: (multiplier * total + bias) * continuing_multiplier
  // + continuing_bias, each step rounded (precise: no fused multiply-add).
  precise float cost = row_cost(x, q, w, texelFetch(frame_cost, int(frame)).xy) * p.continuing_multiplier;
  cost = cost + p.continuing_bias;
  return isnan(cost) ? uvec2(kNone, kNone) : uvec2(orderable_bits(cost), frame);
}

#endif
