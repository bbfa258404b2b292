// The calibration loop that brute force is held to: a plain vectorized
// loop doing the same arithmetic as an exact cost (a subtract, a multiply
// and an add per row·dim, no FMA, since costs must stay bit-identical with
// the reference), over the same rows, queries and threads as the
// `real/<set>/<stream>/fast-brute` rows. It keeps only the minimum (no
// channel weights, multipliers, biases or flags: those cost per row, not per
// row·dim), so it is what the arithmetic alone costs on this machine.
//
//   build/bench/mmvk_bench --benchmark_filter='real/volume/transition/(plain-loop|fast-brute)/B:1024'
//
// The loop is the obvious one: the rows transposed into 16-row tiles
// ([tile][dim][16], what any SIMD loop over rows wants), queries split over
// the threads, and for each block of rows that fits in L2 every query of the
// thread walks it, four tiles at a time (four independent sums hide the add
// latency). plain-loop: the widest of AVX-512F / AVX2 / SSE2 that the CPU
// runs; plain-loop-avx2: the 256-bit loop, the yardstick of the AVX2
// kernels (fast-brute-avx2) on a CPU that also has AVX-512F.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "query_streams.hpp"

namespace mmvk::bench {
namespace {

constexpr std::size_t kRows = 16;        // rows per tile
constexpr std::size_t kBlockTiles = 64;  // 1024 rows x 27 dims = 110 KB: one L2-sized block

using V4 = float __attribute__((vector_size(16)));
using V8 = float __attribute__((vector_size(32)));
using V16 = float __attribute__((vector_size(64)));

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

// Minimum over tiles [first, last) of sum_d (x - q)^2, one query. Returns the
// lane-wise minimum folded to a scalar.
template <class V>
inline __attribute__((always_inline)) float block_min(const float* tiles, std::size_t dims, std::size_t first,
                                                      std::size_t last, const float* q, float best) {
  constexpr std::size_t W = sizeof(V) / sizeof(float);
  constexpr std::size_t P = kRows / W;  // vectors per tile
  constexpr std::size_t T = 4;          // tiles at once
  V low = V{} + best;
  std::size_t tile = first;
  for (; tile + T <= last; tile += T) {
    V sum[T][P];
    for (std::size_t t = 0; t < T; ++t)
      for (std::size_t p = 0; p < P; ++p) sum[t][p] = V{} + 0.0f;
    for (std::size_t d = 0; d < dims; ++d) {
      for (std::size_t t = 0; t < T; ++t) {
        for (std::size_t p = 0; p < P; ++p) {
          V x;
          std::memcpy(&x, tiles + ((tile + t) * dims + d) * kRows + p * W, sizeof(V));
          const V diff = x - q[d];
          sum[t][p] += diff * diff;
        }
      }
    }
    for (std::size_t t = 0; t < T; ++t)
      for (std::size_t p = 0; p < P; ++p) low = sum[t][p] < low ? sum[t][p] : low;
  }
  float out = best;
  for (std::size_t lane = 0; lane < W; ++lane) out = std::min(out, low[lane]);
  (void)tile;  // kBlockTiles is a multiple of T; the tail tiles are padding
  return out;
}

using MinFn = float (*)(const float*, std::size_t, std::size_t, std::size_t, const float*, float);

float min_sse2(const float* x, std::size_t d, std::size_t a, std::size_t b, const float* q, float best) {
  return block_min<V4>(x, d, a, b, q, best);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#pragma GCC push_options
#pragma GCC target("avx2")
float min_avx2(const float* x, std::size_t d, std::size_t a, std::size_t b, const float* q, float best) {
  return block_min<V8>(x, d, a, b, q, best);
}
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f")
float min_avx512(const float* x, std::size_t d, std::size_t a, std::size_t b, const float* q, float best) {
  return block_min<V16>(x, d, a, b, q, best);
}
#pragma GCC pop_options
#endif

// The loop of one instruction set: `avx2_only` holds the 256-bit loop
// (the plain-loop-avx2 rows, beside fast-brute-avx2), else the widest the
// CPU runs. {nullptr, reason} when the CPU lacks the set.
std::pair<MinFn, const char*> pick(bool avx2_only) {
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  if (!avx2_only && __builtin_cpu_supports("avx512f")) return {min_avx512, "avx512f"};
  if (__builtin_cpu_supports("avx2")) return {min_avx2, "avx2"};
#endif
  if (avx2_only) return {nullptr, "no AVX2 on this CPU"};
  return {min_sse2, "sse2"};
}

void plain_loop(benchmark::State& state, DataSet set, QueryStream stream, bool avx2_only) {
  const Database* db = database(set);
  if (db == nullptr) {
    state.SkipWithError("database unavailable (see stderr)");
    return;
  }
  const auto [fn, isa] = pick(avx2_only);
  if (fn == nullptr) {
    state.SkipWithError(isa);
    return;
  }
  const std::size_t batch = static_cast<std::size_t>(state.range(0));
  const std::size_t dims = db->dims();
  const std::size_t frames = db->frame_count();
  // Padded to whole blocks with rows far away (never the minimum).
  const std::size_t tiles = (frames + kRows * kBlockTiles - 1) / (kRows * kBlockTiles) * kBlockTiles;
  std::vector<float> x(tiles * dims * kRows, 1e18f);
  for (std::size_t f = 0; f < frames; ++f) {
    const std::span<const float> row = db->row(static_cast<std::uint32_t>(f));
    for (std::size_t d = 0; d < dims; ++d) x[((f / kRows) * dims + d) * kRows + f % kRows] = row[d];
  }
  const std::vector<float> queries = make_queries(*db, stream, batch);
  ThreadPool pool;  // all cores, as the fixture of the fast-brute rows
  std::vector<float> best(batch);
  const double cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    pool.parallel_for(batch, [&](std::size_t first, std::size_t last, unsigned) {
      for (std::size_t q = first; q < last; ++q) best[q] = std::numeric_limits<float>::infinity();
      for (std::size_t block = 0; block < tiles; block += kBlockTiles) {
        for (std::size_t q = first; q < last; ++q) {
          best[q] = fn(x.data(), dims, block, block + kBlockTiles, queries.data() + q * dims, best[q]);
        }
      }
    });
    benchmark::DoNotOptimize(best.data());
  }
  state.counters["cpu_us/q"] =
      (process_cpu_seconds() - cpu_start) * 1e6 / (double(state.iterations()) * double(batch));
  state.SetLabel(isa);
  state.counters["queries/s"] = benchmark::Counter(double(batch), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["row_dims/s"] =
      benchmark::Counter(double(batch) * double(frames) * double(dims), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["frames"] = double(frames);
}

const bool registered = [] {
  for (DataSet set : {DataSet::Locomotion, DataSet::Volume, DataSet::VolumeMirrored}) {
    for (QueryStream stream : {QueryStream::Transition}) {
      for (const bool avx2_only : {false, true}) {
        const std::string name = "real/" + std::string(data_set_name(set)) + "/" + std::string(query_stream_name(stream)) +
                                 (avx2_only ? "/plain-loop-avx2" : "/plain-loop");
        auto* b = benchmark::RegisterBenchmark(name.c_str(), plain_loop, set, stream, avx2_only);
        b->ArgName("B")->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace mmvk::bench
