// Cluster search, pass 1: one invocation per (cluster, query) writes the
// cluster's lower bound for the query as an orderable key, or kSkip when the
// cluster holds no candidate (ClusterSearch's rules: empty, all members
// do-not-use / edge-excluded / block-transition, tag union misses
// require_all, tag intersection hits exclude_any, contradictory masks), and
// the channel-weighted squared distance of the query to the centroid (the
// seed is the nearest cluster, as ClusterSearch's seed_nearest; nprobe mode
// also probes by it).
//
// The bound is ClusterSearch's box bound (cluster_bound.glsl).
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"
#include "cluster_bound.glsl"

void main() {
  const uint c = gl_GlobalInvocationID.x;
  if (c >= pc.cluster_count) return;
  const uint local_query = gl_WorkGroupID.y;
  const uint query = pc.query_base + local_query;
  const QueryGpu p = query_params[query];
  const uvec4 info = texelFetch(cluster_info, int(c * 3u));
  const uvec4 tags = texelFetch(cluster_info, int(c * 3u + 1u));
  const uvec4 scale = texelFetch(cluster_info, int(c * 3u + 2u));
  const bool skip = info.y == info.z || (info.x & kNeverCandidate) != 0u ||
                    (tags.x & p.require_lo) != p.require_lo || (tags.y & p.require_hi) != p.require_hi ||
                    (tags.z & p.exclude_lo) != 0u || (tags.w & p.exclude_hi) != 0u ||
                    (p.require_lo & p.exclude_lo) != 0u || (p.require_hi & p.exclude_hi) != 0u;
  uvec2 keys = uvec2(kSkip, kSkip);
  if (!skip) {
    vec4 q[DV];
    vec4 lo[DV];
    vec4 hi[DV];
    vec4 center[DV];
    float w[CHANNELS];
    load_query(query, q, w);
    [[unroll]] for (uint v = 0; v < DV; ++v) {
      lo[v] = texelFetch(cluster_vectors, int((c * 3u) * DV + v));
      hi[v] = texelFetch(cluster_vectors, int((c * 3u + 1u) * DV + v));
      center[v] = texelFetch(cluster_vectors, int((c * 3u + 2u) * DV + v));
    }
    keys.x = bound_key(box_total(q, w, lo, hi), scale.xy);
    keys.y = orderable_bits(box_total(q, w, center, center));
  }
  bound_keys[local_query * pc.cluster_count + c] = keys;
}
