// Vectorized across rows: one 16-lane vector holds one dimension of 16
// consecutive rows, so each lane performs exactly the reference's scalar
// sequence (diff, square, channel sum in dim order, weighted total in
// channel order, multiplier, bias) and the costs are bit-identical. Built
// like the rest of the library with -ffp-contract=off (no fused multiply-add).
#include "fast_search_kernels.hpp"

#include <cstring>

namespace mmvk::detail {

namespace {

using V16 = float __attribute__((vector_size(64)));
using I16 = std::int32_t __attribute__((vector_size(64)));
using I8 = std::int32_t __attribute__((vector_size(32)));
using I4 = std::int32_t __attribute__((vector_size(16)));

#define MMVK_INLINE inline __attribute__((always_inline))

// The helpers below take and return vectors but are always inlined inside
// this file, so the ABI note GCC gives for 64-byte vectors does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

MMVK_INLINE V16 load(const float* p) {
  V16 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

MMVK_INLINE I16 load_mask(const std::int32_t* p) {
  I16 v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

MMVK_INLINE bool any_lane(const I16& m) {
  const I8 a = __builtin_shufflevector(m, m, 0, 1, 2, 3, 4, 5, 6, 7) |
               __builtin_shufflevector(m, m, 8, 9, 10, 11, 12, 13, 14, 15);
  const I4 b = __builtin_shufflevector(a, a, 0, 1, 2, 3) | __builtin_shufflevector(a, a, 4, 5, 6, 7);
  std::uint64_t lo = 0;
  std::uint64_t hi = 0;
  std::memcpy(&lo, &b, 8);
  std::memcpy(&hi, reinterpret_cast<const char*>(&b) + 8, 8);
  return (lo | hi) != 0;
}

template <int Q>
MMVK_INLINE std::size_t evaluate_tiles_q(const TileArrays& t, const KernelQuery* queries, const std::uint32_t* tile_ids,
                                         std::size_t count, LaneHit* hits) {
  std::size_t hit_count = 0;
  const std::size_t tile_floats = std::size_t{t.dims} * kLanes;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t tile = tile_ids[i];
    const float* x = t.features + tile * tile_floats;
    V16 total[Q];
    for (int q = 0; q < Q; ++q) total[q] = V16{} + 0.0f;
    std::uint32_t d = 0;
    for (std::uint32_t c = 0; c < t.channels; ++c) {
      const std::uint32_t end = t.channel_end[c];
      V16 sum[Q];
      for (int q = 0; q < Q; ++q) sum[q] = V16{} + 0.0f;
      for (; d < end; ++d) {
        const V16 row = load(x + std::size_t{d} * kLanes);
        for (int q = 0; q < Q; ++q) {
          const V16 diff = row - queries[q].features[d];
          sum[q] += diff * diff;
        }
      }
      for (int q = 0; q < Q; ++q) total[q] += queries[q].weights[c] * sum[q];
    }
    const V16 multiplier = load(t.multiplier + std::size_t{tile} * kLanes);
    const V16 bias = load(t.bias + std::size_t{tile} * kLanes);
    const I16 valid = load_mask(t.lane_valid + std::size_t{tile} * kLanes);
    for (int q = 0; q < Q; ++q) {
      const V16 cost = multiplier * total[q] + bias;
      const I16 pass = (cost <= queries[q].threshold) & valid;
      if (!any_lane(pass)) continue;
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        if (pass[lane] != 0) hits[hit_count++] = LaneHit{tile * kLanes + lane, cost[lane], std::uint32_t(q)};
      }
    }
  }
  return hit_count;
}

}  // namespace

// One clone per instruction set; the dynamic loader picks the best one.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MMVK_KERNEL_CLONES __attribute__((target_clones("default", "avx2", "avx512f")))
#else
#define MMVK_KERNEL_CLONES
#endif

MMVK_KERNEL_CLONES
std::size_t evaluate_tiles(const TileArrays& tiles, const KernelQuery* queries, std::uint32_t query_count,
                           const std::uint32_t* tile_ids, std::size_t count, LaneHit* hits) {
  switch (query_count) {
    case 1: return evaluate_tiles_q<1>(tiles, queries, tile_ids, count, hits);
    case 2: return evaluate_tiles_q<2>(tiles, queries, tile_ids, count, hits);
    default: return evaluate_tiles_q<4>(tiles, queries, tile_ids, count, hits);
  }
}

// The bound mirrors the cost's operation order with each |x - q| replaced by
// the distance from q to the box (0 inside it). Rounding is monotonic, so
// every step stays <= the matching step of any row in the box, and the
// bound never exceeds a member's computed cost.
MMVK_KERNEL_CLONES
void box_bounds(const BoxArrays& b, std::size_t pack, const float* query, const float* weights, float* out) {
  const float* lo = b.lo + pack * b.dims * kLanes;
  const float* hi = b.hi + pack * b.dims * kLanes;
  V16 total = V16{} + 0.0f;
  std::uint32_t d = 0;
  for (std::uint32_t c = 0; c < b.channels; ++c) {
    const std::uint32_t end = b.channel_end[c];
    V16 sum = V16{} + 0.0f;
    for (; d < end; ++d) {
      const V16 below = load(lo + std::size_t{d} * kLanes) - query[d];
      const V16 above = query[d] - load(hi + std::size_t{d} * kLanes);
      V16 diff = below > above ? below : above;
      diff = diff > 0.0f ? diff : V16{} + 0.0f;
      sum += diff * diff;
    }
    total += weights[c] * sum;
  }
  const V16 bound = load(b.min_multiplier + pack * kLanes) * total + load(b.min_bias + pack * kLanes);
  std::memcpy(out, &bound, sizeof(bound));
}

}  // namespace mmvk::detail
