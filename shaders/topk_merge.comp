// Exact search, pass 2 of 2: one invocation per query merges the per-block
// best K pairs written by the scan pass into the query's final best K,
// sorted by (cost, frame). The block loop runs block_count (<= 16k)
// iterations; the per-block loop is unrolled (llvmpipe's loop limit).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "search_layout.glsl"

layout(local_size_x_id = 0) in;
layout(constant_id = 4) const uint K = 1;

void main() {
  const uint local_query = gl_GlobalInvocationID.x;
  if (local_query >= pc.query_count) return;

  uvec2 best[K];
  [[unroll]] for (uint j = 0; j < K; ++j) best[j] = uvec2(kNone, kNone);

  const uint base = local_query * pc.block_count * K;
  for (uint block = 0; block < pc.block_count; ++block) {
    [[unroll]] for (uint i = 0; i < K; ++i) {
      const uvec2 candidate = scratch[base + block * K + i];
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
  }

  const uint out_base = (pc.query_base + local_query) * K;
  [[unroll]] for (uint j = 0; j < K; ++j) results[out_base + j] = best[j];
}
