// ClusterSearch's box bound (mmvk/cluster_search.hpp), shared by the
// cluster bounds (one box per cluster) and the block culling (one box per
// member block): per channel (weight 0 skipped) a float sum of gap_d^2 in
// dim order, gap_d the distance of q_d to [lo_d, hi_d], total += w * sum;
// then min_multiplier * total + min_bias. Each rounding step is monotone and
// at most the matching step of a member's own cost, so the bound never
// exceeds a member's cost; `precise` keeps that order on fusing GPUs.
// Needs kernel_shape.glsl, search_layout.glsl and search_cost.glsl.
#ifndef MMVK_CLUSTER_BOUND_GLSL
#define MMVK_CLUSTER_BOUND_GLSL

// The channel-weighted squared distance of q to the box [lo, hi]; a box of
// zero size (lo = hi = centroid) gives the nprobe centroid distance.
float box_total(vec4 q[DV], float w[CHANNELS], vec4 lo[DV], vec4 hi[DV]) {
  precise float total = 0.0;
  precise float sum = 0.0;
  uint ch = 0u;
  [[unroll]] for (uint d = 0; d < DIMS; ++d) {
    const float qd = q[d >> 2u][d & 3u];
    // At most one of below/above is > 0 (lo <= hi).
    precise float below = lo[d >> 2u][d & 3u] - qd;
    precise float above = qd - hi[d >> 2u][d & 3u];
    const float outside = below > above ? below : above;
    const float gap = outside > 0.0 ? outside : 0.0;
    sum = sum + gap * gap;
    if (ends_channel(d)) {
      if (w[ch] != 0.0) total = total + w[ch] * sum;
      sum = 0.0;
      ++ch;
    }
  }
  return total;
}

// The orderable key of min_multiplier * total + min_bias (bits of both in
// `scale`); a NaN bound (0 * inf) prunes nothing, as in ClusterSearch.
uint bound_key(float total, uvec2 scale) {
  precise float bound = uintBitsToFloat(scale.x) * total;
  bound = bound + uintBitsToFloat(scale.y);
  return isnan(bound) ? 0u : orderable_bits(bound);
}

#endif
