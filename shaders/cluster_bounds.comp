// Cluster search, pass 1: for each (cluster, query), writes the
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

// The cluster's (bound key, centroid distance key) for the query (q, w)
// and its rule parameters p.
uvec2 cluster_keys(uint c, QueryGpu p, vec4 q[DV], float w[CHANNELS]) {
  const uvec4 info = texelFetch(cluster_info, int(c * 3u));
  const uvec4 tags = texelFetch(cluster_info, int(c * 3u + 1u));
  const uvec4 scale = texelFetch(cluster_info, int(c * 3u + 2u));
  const bool skip = info.y == info.z || (info.x & kNeverCandidate) != 0u ||
                    (tags.x & p.require_lo) != p.require_lo || (tags.y & p.require_hi) != p.require_hi ||
                    (tags.z & p.exclude_lo) != 0u || (tags.w & p.exclude_hi) != 0u ||
                    (p.require_lo & p.exclude_lo) != 0u || (p.require_hi & p.exclude_hi) != 0u;
  if (skip) return uvec2(kSkip, kSkip);
  vec4 lo[DV];
  vec4 hi[DV];
  vec4 center[DV];
  [[unroll]] for (uint v = 0; v < DV; ++v) {
    lo[v] = texelFetch(cluster_vectors, int((c * 3u) * DV + v));
    hi[v] = texelFetch(cluster_vectors, int((c * 3u + 1u) * DV + v));
    center[v] = texelFetch(cluster_vectors, int((c * 3u + 2u) * DV + v));
  }
  return uvec2(bound_key(box_total(q, w, lo, hi), scale.xy), orderable_bits(box_total(q, w, center, center)));
}

// Invocation x of a query's row of workgroups takes clusters x, x + stride,
// ... (kClustersPerBoundsInvocation at most): the query's features, weights
// and parameters are loaded once for them (storage-buffer loads are scalar
// loops over the lanes on lavapipe; one load per (cluster, query) was about
// half of this pass).
void main() {
  // Lanes with no cluster load nothing: with fewer clusters than a
  // workgroup's lanes (small databases), their loads would be most of it.
  if (gl_GlobalInvocationID.x >= pc.cluster_count) return;
  const uint local_query = gl_WorkGroupID.y;
  const uint query = pc.query_base + local_query;
  const QueryGpu p = query_params_of(query);
  vec4 q[DV];
  float w[CHANNELS];
  load_query(query, q, w);
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint c = gl_GlobalInvocationID.x; c < pc.cluster_count; c += stride) {
    bound_keys[local_query * pc.cluster_count + c] = cluster_keys(c, p, q, w);
  }
}
