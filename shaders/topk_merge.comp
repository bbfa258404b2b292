// Exact search, pass 2 of 2: one invocation per query merges the per-block
// best K pairs written by the scan pass into the query's final best K,
// sorted by (cost, frame). The block loop runs block_count (<= 16k)
// iterations; the per-block loop is unrolled (llvmpipe's loop limit).
// With ADD_CONTINUING (brute_force_scan.comp, which skips it), it also
// evaluates each query's continuing frame, continuing_bias included.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "search_layout.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 4) const uint K = 1;
layout(constant_id = 10) const bool ADD_CONTINUING = false;
// The database shape, for the continuing frame's cost.
layout(constant_id = 1) const uint DV = 1;        // padded dims / 4
layout(constant_id = 2) const uint DIMS = 1;      // real dims (<= 128)
layout(constant_id = 5) const uint CHANNELS = 1;  // non-empty channels
// Bit d set: dimension d is the last of its channel.
layout(constant_id = 6) const uint END_MASK_0 = 0u;
layout(constant_id = 7) const uint END_MASK_1 = 0u;
layout(constant_id = 8) const uint END_MASK_2 = 0u;
layout(constant_id = 9) const uint END_MASK_3 = 0u;

#include "search_cost.glsl"

void insert(inout uvec2 best[K], uvec2 candidate) {
  if (pair_less(candidate, best[K - 1u])) {
    best[K - 1u] = candidate;
    [[unroll]] for (uint j = K - 1u; j > 0u; --j) {
      if (pair_less(best[j], best[j - 1u])) {
        const uvec2 swap = best[j];
        best[j] = best[j - 1u];
        best[j - 1u] = swap;
      }
    }
  }
}

// The (cost, frame) pair of query `query`'s continuing frame, or
// (kNone, kNone) when it has none or it is not a candidate.
uvec2 continuing_pair(uint query) {
  const QueryGpu p = query_params[query];
  const uint frame = p.continuing_frame;
  if (frame >= pc.frame_count) return uvec2(kNone, kNone);
  if (!frame_is_candidate(frame, texelFetch(frame_meta, int(frame)), true, p)) return uvec2(kNone, kNone);
  vec4 x[DV];
  vec4 q[DV];
  float w[CHANNELS];
  [[unroll]] for (uint v = 0; v < DV; ++v) {
    x[v] = texelFetch(features, int(frame * DV + v));
    q[v] = query_features[query * DV + v];
  }
  [[unroll]] for (uint c = 0; c < CHANNELS; ++c) w[c] = query_weights[query * CHANNELS + c];
  precise float cost = row_cost(x, q, w, texelFetch(frame_cost, int(frame)).xy) + p.continuing_bias;
  return isnan(cost) ? uvec2(kNone, kNone) : uvec2(orderable_bits(cost), frame);
}

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;

  uvec2 best[K];
  [[unroll]] for (uint j = 0; j < K; ++j) best[j] = uvec2(kNone, kNone);

  const uint base = local_query * pc.block_count * K;
  for (uint block = 0; block < pc.block_count; ++block) {
    [[unroll]] for (uint i = 0; i < K; ++i) insert(best, scratch[base + block * K + i]);
  }
  if (ADD_CONTINUING) insert(best, continuing_pair(pc.query_base + local_query));

  const uint out_base = (pc.query_base + local_query) * K;
  [[unroll]] for (uint j = 0; j < K; ++j) results[out_base + j] = best[j];
}
