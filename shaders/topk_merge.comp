// Exact search, pass 2 of 2: one invocation per query merges the per-block
// best K pairs written by the scan pass into the query's final best K,
// sorted by (cost, frame). The block loop runs block_count (<= 16k)
// iterations; the per-block loop is unrolled (llvmpipe's loop limit).
// With ADD_CONTINUING (brute_force_scan.comp, which skips it), it also
// evaluates each query's continuing frame, continuing_multiplier and continuing_bias included.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "search_layout.glsl"
#include "search_cost.glsl"
#include "top_k.glsl"

layout(constant_id = 10) const bool ADD_CONTINUING = false;

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;

  uvec2 best[K];
  clear_pairs(best);

  const uint base = local_query * pc.block_count * K;
  for (uint block = 0; block < pc.block_count; ++block) {
    [[unroll]] for (uint i = 0; i < K; ++i) insert_pair(best, scratch[base + block * K + i]);
  }
  if (ADD_CONTINUING) {
    const uint query = pc.query_base + local_query;
    vec4 q[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    insert_pair(best, continuing_pair(query, q, w));
  }

  const uint out_base = (pc.query_base + local_query) * K;
  [[unroll]] for (uint j = 0; j < K; ++j) results[out_base + j] = best[j];
}
