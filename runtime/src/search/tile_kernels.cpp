// Vectorized across rows: one 16-lane vector holds one dimension of 16
// consecutive rows, so each lane performs exactly the reference's scalar
// sequence (diff, square, channel sum in dim order, weighted total in
// channel order, multiplier, bias) and the costs are bit-identical. Built
// like the rest of the library with -ffp-contract=off (no fused multiply-add).
//
// Each instruction set gets its own copy (#pragma GCC target) and
// select_kernels() picks one set of function pointers per backend, rather
// than target_clones resolving each function on its own: the choice can be
// forced to the baseline (tests hold every copy to the reference), AVX-512
// is covered, and callers can see which set runs (kernel_name()). Measured
// against ClusterSearch's former AVX2 target_clones, it was no slower.
#include "search/tile_kernels.hpp"

#include <cstring>

#include "search/half_float.hpp"

#if defined(__x86_64__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace mmvk::detail {

namespace {

// Native vector widths: 4 lanes (SSE2, the x86-64 baseline), 8 (AVX2), 16
// (AVX-512). A 16-row tile is 16 / width vectors. Wider-than-native generic
// vectors would make GCC spill every accumulator to memory.
using V4 = float __attribute__((vector_size(16)));
using V8 = float __attribute__((vector_size(32)));
using V16 = float __attribute__((vector_size(64)));
template <class V> struct MaskOf;
template <> struct MaskOf<V4> { using type = std::int32_t __attribute__((vector_size(16))); };
template <> struct MaskOf<V8> { using type = std::int32_t __attribute__((vector_size(32))); };
template <> struct MaskOf<V16> { using type = std::int32_t __attribute__((vector_size(64))); };

#define MMVK_INLINE inline __attribute__((always_inline))
#define MMVK_INLINE_LAMBDA __attribute__((always_inline))

// The helpers below take and return vectors but are always inlined into
// this file's entry points, so the ABI note GCC and Clang give for them is
// moot.
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

template <class T>
MMVK_INLINE T load(const void* p) {
  T v;
  std::memcpy(&v, p, sizeof(v));
  return v;
}

template <class M>
MMVK_INLINE bool any_lane(const M& m) {
  std::uint64_t words[sizeof(M) / 8];
  std::memcpy(words, &m, sizeof(M));
  std::uint64_t any = 0;
  for (std::uint64_t w : words) any |= w;
  return any != 0;
}

// The squares of dim d of T tiles' rows against Q queries, into sums
// (Assign: the channel's first dim, sum = square) or added to them. The
// difference is taken as q - x, the exact negation of the reference's x - q
// (round to nearest is symmetric), so its square is the same bits, and the
// row can stay a memory operand of the subtraction.
template <bool Assign, class V, int Q, int T, int P>
MMVK_INLINE void accumulate_dim(const float* const (&x)[T], const KernelQuery* queries, std::uint32_t d,
                                V (&sum)[Q][T][P]) {
  constexpr int W = sizeof(V) / sizeof(float);
  V row[T][P];
  for (int j = 0; j < T; ++j)
    for (int p = 0; p < P; ++p) row[j][p] = load<V>(x[j] + std::size_t{d} * kLanes + p * W);
  for (int q = 0; q < Q; ++q) {
    const float value = queries[q].features[d];
    for (int j = 0; j < T; ++j) {
      for (int p = 0; p < P; ++p) {
        const V diff = value - row[j][p];
        if constexpr (Assign) {
          sum[q][j][p] = diff * diff;
        } else {
          sum[q][j][p] += diff * diff;
        }
      }
    }
  }
}

// The costs of the lanes from lane0 on, from their weighted totals.
template <class V>
MMVK_INLINE V row_cost(const TileArrays& t, std::size_t lane0, const V& total) {
  return load<V>(t.multiplier + lane0) * total + load<V>(t.bias + lane0);
}

// Visits every vector of a group of T tiles for every query: its first
// lane, the query, the vector's costs and its passing lanes (rows within
// the query's threshold). `total` is the weighted channel sums.
template <class V, int Q, int T, int P, class Visit>
MMVK_INLINE void visit_costs(const TileArrays& t, const KernelQuery* queries, const std::uint32_t* tile,
                             const V (&total)[Q][T][P], Visit&& visit) {
  using M = typename MaskOf<V>::type;
  constexpr int W = sizeof(V) / sizeof(float);
  for (int j = 0; j < T; ++j) {
    for (int p = 0; p < P; ++p) {
      const std::size_t lane0 = std::size_t{tile[j]} * kLanes + p * W;
      const M valid = load<M>(t.lane_valid + lane0);
      for (int q = 0; q < Q; ++q) {
        const V cost = row_cost(t, lane0, total[q][j][p]);
        visit(lane0, q, cost, M((cost <= queries[q].threshold) & valid));
      }
    }
  }
}

// Evaluates T tiles at once: with one 16-lane vector per tile (AVX-512)
// and one query, a single tile is one chain of dependent adds and runs at
// the add latency; T independent tiles keep the adder busy. Every lane's
// arithmetic is unchanged.
//
// What the plain loop (bench/plain_loop_bench.cpp) does not pay is kept
// small, so that the kernels run at its rate: a channel's sum starts as its
// first dim's square (the reference's 0 + square is that square, bit for
// bit: a square is +0, positive, +inf or NaN), so a channel costs the
// plain loop's adds plus one for its weighted total; and a group of tiles
// tests its passing lanes once, not once per vector and query (lanes rarely
// pass: the threshold is the k-th best so far).
template <class V, int Q, int T>
MMVK_INLINE std::size_t evaluate_tile_group(const TileArrays& t, const KernelQuery* queries, const std::uint32_t* tile,
                                            LaneHit* hits) {
  using M = typename MaskOf<V>::type;
  constexpr int W = sizeof(V) / sizeof(float);
  constexpr int P = kLanes / W;
  std::size_t hit_count = 0;
  const std::size_t tile_floats = std::size_t{t.dims} * kLanes;
  const float* x[T];
  for (int j = 0; j < T; ++j) x[j] = t.features + tile[j] * tile_floats;
  V total[Q][T][P];
  for (int q = 0; q < Q; ++q)
    for (int j = 0; j < T; ++j)
      for (int p = 0; p < P; ++p) total[q][j][p] = V{} + 0.0f;
  std::uint32_t d = 0;
  for (std::uint32_t c = 0; c < t.channels; ++c) {
    const std::uint32_t end = t.channel_end[c];
    V sum[Q][T][P];
    if (d < end) {
      accumulate_dim<true>(x, queries, d, sum);
      for (++d; d < end; ++d) accumulate_dim<false>(x, queries, d, sum);
    } else {
      for (int q = 0; q < Q; ++q)
        for (int j = 0; j < T; ++j)
          for (int p = 0; p < P; ++p) sum[q][j][p] = V{} + 0.0f;
    }
    for (int q = 0; q < Q; ++q)
      for (int j = 0; j < T; ++j)
        for (int p = 0; p < P; ++p) total[q][j][p] += queries[q].weights[c] * sum[q][j][p];
  }
  // Costs and passing lanes are computed again after the one test (rare),
  // rather than kept; and the test ORs each vector's any_lane, not the
  // lane masks (either made GCC compare AVX-512 lanes one by one).
  bool any_pass = false;
  visit_costs(t, queries, tile, total,
              [&](std::size_t, int, const V&, const M& pass) MMVK_INLINE_LAMBDA { any_pass |= any_lane(pass); });
  if (!any_pass) return 0;
  visit_costs(t, queries, tile, total, [&](std::size_t lane0, int q, const V& cost, const M& pass) MMVK_INLINE_LAMBDA {
    if (!any_lane(pass)) return;
    for (int lane = 0; lane < W; ++lane) {
      if (pass[lane] != 0) {
        hits[hit_count++] = LaneHit{static_cast<std::uint32_t>(lane0) + lane, cost[lane], std::uint32_t(q)};
      }
    }
  });
  return hit_count;
}

template <class V, int Q>
MMVK_INLINE std::size_t evaluate_tiles_q(const TileArrays& t, const KernelQuery* queries, const std::uint32_t* tile_ids,
                                         std::size_t count, LaneHit* hits) {
  // Independent sums per pass: 8 vectors with AVX2 (one query: 4 tiles of
  // 2 vectors; 0.84x -> 0.87x the plain loop against 2 tiles, one core,
  // Bandai-sized synthetic rows), 4 otherwise (AVX-512: one vector a tile;
  // SSE2: 4 vectors a tile already, and 16 registers).
  constexpr int W = sizeof(V) / sizeof(float);
  constexpr int P = kLanes / W;
  constexpr int kSums = W == 8 ? 8 : 4;
  constexpr int T = Q * P >= kSums ? 1 : kSums / (Q * P);
  std::size_t hit_count = 0;
  std::size_t i = 0;
  if constexpr (T > 1) {
    for (; i + T <= count; i += T) hit_count += evaluate_tile_group<V, Q, T>(t, queries, tile_ids + i, hits + hit_count);
  }
  for (; i < count; ++i) hit_count += evaluate_tile_group<V, Q, 1>(t, queries, tile_ids + i, hits + hit_count);
  return hit_count;
}

template <class V>
MMVK_INLINE std::size_t evaluate_tiles_v(const TileArrays& tiles, const KernelQuery* queries,
                                         std::uint32_t query_count, const std::uint32_t* tile_ids, std::size_t count,
                                         LaneHit* hits) {
  switch (query_count) {
    case 1: return evaluate_tiles_q<V, 1>(tiles, queries, tile_ids, count, hits);
    case 2: return evaluate_tiles_q<V, 2>(tiles, queries, tile_ids, count, hits);
    default: return evaluate_tiles_q<V, 4>(tiles, queries, tile_ids, count, hits);
  }
}

// The squared distance from q to [lo, hi] of the lanes at lo + at, hi + at.
template <class V>
MMVK_INLINE V gap_squared(const float* lo, const float* hi, std::size_t at, float q) {
  // At most one of below and above is > 0 (lo <= hi).
  const V below = load<V>(lo + at) - q;
  const V above = q - load<V>(hi + at);
  V diff = below > above ? below : above;
  diff = diff > 0.0f ? diff : V{} + 0.0f;
  return diff * diff;
}

// T packs of 16 boxes at once, from `pack` on (see box_bounds_v).
template <class V, int T>
MMVK_INLINE void box_bounds_group(const BoxArrays& b, std::size_t pack, const float* query, const float* weights,
                                  float* out) {
  constexpr int W = sizeof(V) / sizeof(float);
  constexpr int P = kLanes / W;
  const float* lo = b.lo + pack * b.dims * kLanes;
  const float* hi = b.hi + pack * b.dims * kLanes;
  const std::size_t pack_floats = std::size_t{b.dims} * kLanes;
  auto at = [&](int j, int p, std::uint32_t d) { return j * pack_floats + std::size_t{d} * kLanes + p * W; };
  V total[T][P];
  for (int j = 0; j < T; ++j)
    for (int p = 0; p < P; ++p) total[j][p] = V{} + 0.0f;
  std::uint32_t d = 0;
  for (std::uint32_t c = 0; c < b.channels; ++c) {
    const std::uint32_t end = b.channel_end[c];
    if (weights[c] == 0.0f) {
      d = end;
      continue;
    }
    // A channel's sum starts as its first dim's square, as in
    // evaluate_tile_group.
    V sum[T][P];
    for (int j = 0; j < T; ++j)
      for (int p = 0; p < P; ++p) sum[j][p] = d < end ? gap_squared<V>(lo, hi, at(j, p, d), query[d]) : V{} + 0.0f;
    for (++d; d < end; ++d) {
      for (int j = 0; j < T; ++j)
        for (int p = 0; p < P; ++p) sum[j][p] += gap_squared<V>(lo, hi, at(j, p, d), query[d]);
    }
    d = end;
    for (int j = 0; j < T; ++j)
      for (int p = 0; p < P; ++p) total[j][p] += weights[c] * sum[j][p];
  }
  for (int j = 0; j < T; ++j) {
    for (int p = 0; p < P; ++p) {
      const std::size_t lane0 = (pack + j) * kLanes + p * W;
      const V bound = load<V>(b.min_multiplier + lane0) * total[j][p] + load<V>(b.min_bias + lane0);
      std::memcpy(out + j * kLanes + p * W, &bound, sizeof(bound));
    }
  }
}

// The bound mirrors the cost's operation order with each |x - q| replaced by
// the distance from q to the box (0 inside it). Rounding is monotonic, so
// every step stays <= the matching step of any row in the box, and the
// bound never exceeds a member's computed cost. A channel of weight 0 adds
// +0 to a member's total, so skipping it changes no bound (and avoids
// 0 x inf when a far box overflows). Consecutive packs are bounded T at a
// time (independent sums, as in evaluate_tiles_q).
template <class V>
MMVK_INLINE void box_bounds_v(const BoxArrays& b, std::size_t first_pack, std::size_t pack_count, const float* query,
                              const float* weights, float* out) {
  constexpr int P = kLanes / (sizeof(V) / sizeof(float));
  constexpr int T = P >= 4 ? 1 : 4 / P;
  std::size_t pack = first_pack;
  const std::size_t end = first_pack + pack_count;
  if constexpr (T > 1) {
    for (; pack + T <= end; pack += T, out += T * kLanes) box_bounds_group<V, T>(b, pack, query, weights, out);
  }
  for (; pack < end; ++pack, out += kLanes) box_bounds_group<V, 1>(b, pack, query, weights, out);
}

#define MMVK_DEFINE_KERNELS(suffix, V)                                                                         \
  std::size_t evaluate_tiles_##suffix(const TileArrays& tiles, const KernelQuery* queries,                    \
                                      std::uint32_t query_count, const std::uint32_t* tile_ids,                \
                                      std::size_t count, LaneHit* hits) {                                      \
    return evaluate_tiles_v<V>(tiles, queries, query_count, tile_ids, count, hits);                            \
  }                                                                                                            \
  void box_bounds_##suffix(const BoxArrays& boxes, std::size_t first_pack, std::size_t pack_count,            \
                           const float* query, const float* weights, float* out) {                             \
    box_bounds_v<V>(boxes, first_pack, pack_count, query, weights, out);                                       \
  }

MMVK_DEFINE_KERNELS(generic, V4)
namespace half_generic {
using V = V4;
struct HalfLoad {
  MMVK_INLINE V operator()(const std::uint16_t* p) const {
    return V{half_to_float(p[0]), half_to_float(p[1]), half_to_float(p[2]), half_to_float(p[3])};
  }
};
struct PassBits {
  MMVK_INLINE std::uint32_t operator()(const V& total, float limit) const {
    std::uint32_t bits = 0;
    for (int lane = 0; lane < 4; ++lane) bits |= !(total[lane] > limit) ? 1u << lane : 0u;
    return bits;
  }
};
#include "search/half_kernels.inc"
}  // namespace half_generic
#if defined(__x86_64__) && defined(__clang__)
// Clang ignores GCC's target pragmas (the kernels would be built for SSE2
// and only named avx2 / avx512f); its own pragma sets the target of every
// function defined in the region, and the always-inline helpers take it
// on when inlined there.
#define MMVK_HAS_X86_KERNELS 1
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
MMVK_DEFINE_KERNELS(avx2, V8)
#pragma clang attribute pop
#pragma clang attribute push(__attribute__((target("avx2,f16c"))), apply_to = function)
#include "search/half_kernels_avx2.inc"
#pragma clang attribute pop
#pragma clang attribute push(__attribute__((target("avx512f"))), apply_to = function)
MMVK_DEFINE_KERNELS(avx512, V16)
#include "search/half_kernels_avx512.inc"
#pragma clang attribute pop
#elif defined(__x86_64__) && defined(__GNUC__)
#define MMVK_HAS_X86_KERNELS 1
#pragma GCC push_options
#pragma GCC target("avx2")
MMVK_DEFINE_KERNELS(avx2, V8)
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx2,f16c")
#include "search/half_kernels_avx2.inc"
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f")
MMVK_DEFINE_KERNELS(avx512, V16)
#include "search/half_kernels_avx512.inc"
#pragma GCC pop_options
#endif

Kernels generic_kernels() {
  return {evaluate_tiles_generic, box_bounds_generic, half_generic::half_box_bounds, half_generic::half_filter,
          "generic", 2};
}

#if defined(MMVK_HAS_X86_KERNELS)
// F16C from CPUID leaf 1 (Clang's __builtin_cpu_supports has no "f16c").
bool has_f16c() {
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  return __get_cpuid(1, &eax, &ebx, &ecx, &edx) != 0 && (ecx & bit_F16C) != 0;
}

// AVX2 machines without F16C (none are known) read halves with the
// baseline conversion.
Kernels avx2_kernels() {
  if (!has_f16c()) {
    return {evaluate_tiles_avx2, box_bounds_avx2, half_generic::half_box_bounds, half_generic::half_filter, "avx2", 4};
  }
  return {evaluate_tiles_avx2, box_bounds_avx2, half_avx2::half_box_bounds, half_avx2::half_filter, "avx2", 4};
}
Kernels avx512_kernels() {
  return {evaluate_tiles_avx512, box_bounds_avx512, half_avx512::half_box_bounds, half_avx512::half_filter, "avx512f",
          4};
}
#endif

}  // namespace

Kernels select_kernels(bool baseline) {
#if defined(MMVK_HAS_X86_KERNELS)
  if (baseline) return generic_kernels();
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f")) return avx512_kernels();
  if (__builtin_cpu_supports("avx2")) return avx2_kernels();
#else
  (void)baseline;
#endif
  return generic_kernels();
}

bool select_kernels(CpuKernels set, Kernels& out) {
  switch (set) {
    case CpuKernels::Widest: out = select_kernels(false); return true;
    case CpuKernels::Generic: out = select_kernels(true); return true;
#if defined(MMVK_HAS_X86_KERNELS)
    case CpuKernels::Avx2:
      __builtin_cpu_init();
      if (!__builtin_cpu_supports("avx2")) return false;
      out = avx2_kernels();
      return true;
    case CpuKernels::Avx512:
      __builtin_cpu_init();
      if (!__builtin_cpu_supports("avx512f")) return false;
      out = avx512_kernels();
      return true;
#endif
    default: return false;
  }
}

}  // namespace mmvk::detail
