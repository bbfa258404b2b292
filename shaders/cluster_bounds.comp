// Cluster search, pass 1: one invocation per (cluster, query) writes the
// cluster's lower bound for the query as an orderable key, or kSkip when the
// cluster holds no candidate (ClusterSearch's rules: empty, all members
// do-not-use / edge-excluded / block-transition, tag union misses
// require_all, tag intersection hits exclude_any, contradictory masks).
// In nprobe mode it also writes the channel-weighted squared distance of the
// query to the centroid.
//
// The bound is ClusterSearch's box bound, computed the same way: per channel
// (weight 0 skipped) a float sum of gap_d^2 in dim order, gap_d the distance
// of q_d to [box_min_d, box_max_d], total += w * sum, min_multiplier * total
// + min_bias. Each rounding step is monotone and at most the matching step
// of a member's own cost, so the bound never exceeds a member's cost
// (mmvk/cluster_search.hpp); `precise` keeps the order on fusing GPUs.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

#include "kernel_shape.glsl"
#include "cluster_layout.glsl"
#include "search_cost.glsl"

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
      center[v] = pc.nprobe != 0u ? texelFetch(cluster_vectors, int((c * 3u + 2u) * DV + v)) : vec4(0.0);
    }
    precise float total = 0.0;
    precise float sum = 0.0;
    precise float distance_total = 0.0;
    precise float distance_sum = 0.0;
    uint ch = 0u;
    [[unroll]] for (uint d = 0; d < DIMS; ++d) {
      const float qd = q[d >> 2u][d & 3u];
      // At most one of below/above is > 0 (lo <= hi).
      precise float below = lo[d >> 2u][d & 3u] - qd;
      precise float above = qd - hi[d >> 2u][d & 3u];
      const float outside = below > above ? below : above;
      const float gap = outside > 0.0 ? outside : 0.0;
      sum = sum + gap * gap;
      // The centroid as a zero-size box (ClusterSearch's nprobe distance);
      // skipped in exact mode (a uniform branch).
      if (pc.nprobe != 0u) {
        precise float c_below = center[d >> 2u][d & 3u] - qd;
        precise float c_above = qd - center[d >> 2u][d & 3u];
        const float c_outside = c_below > c_above ? c_below : c_above;
        const float c_gap = c_outside > 0.0 ? c_outside : 0.0;
        distance_sum = distance_sum + c_gap * c_gap;
      }
      if (ends_channel(d)) {
        if (w[ch] != 0.0) {
          total = total + w[ch] * sum;
          distance_total = distance_total + w[ch] * distance_sum;
        }
        sum = 0.0;
        distance_sum = 0.0;
        ++ch;
      }
    }
    precise float bound = uintBitsToFloat(scale.x) * total;
    bound = bound + uintBitsToFloat(scale.y);
    // A NaN bound (0 * inf) prunes nothing, as in ClusterSearch.
    keys.x = isnan(bound) ? 0u : orderable_bits(bound);
    keys.y = pc.nprobe != 0u ? orderable_bits(distance_total) : 0u;
  }
  bound_keys[local_query * pc.cluster_count + c] = keys;
}
