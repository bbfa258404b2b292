// Exact CPU search: the reference vs FastSearch brute force vs FastSearch
// with box pruning, for B in {1, 64, 1024} and the three query streams
// (query_streams.hpp), on synthetic motion-like data of the default 27-d
// schema: 21,791 frames (the Bandai locomotion set's size) and 417,000 (the
// volume set's). register_search_benchmarks() takes any Database provider,
// so real sets plug in the same way.
//
//   build/bench/mmvk_bench --benchmark_filter='^search/'
//
// Counters: queries/s; rows_fraction (rows whose full cost was evaluated,
// per query and frame); row_dims/s (evaluated rows x dims per second, the
// throughput to compare with the machine's limit, see calibration/fma_peak in
// calibration_bench.cpp).
// The reference runs one iteration at B = 1024 and at the large size.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mmvk/search/backends.hpp"
#include "mmvk/search/fast_search.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "query_streams.hpp"

namespace mmvk::bench {

using DatabaseProvider = std::function<const Database*()>;

namespace {

// Clips of smooth random walks in the default schema (normalized units):
// neighbouring frames are close, as in motion capture, so boxes over
// consecutive frames mean something.
Database synthetic_motion_database(std::uint32_t frames, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  DatabaseParts parts;
  parts.schema = default_schema();
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  parts.normalization.assign(dims, DimNormalization{});
  parts.frame_flags.assign(frames, 0);
  parts.features.resize(std::size_t{frames} * dims);
  constexpr std::uint32_t kClipFrames = 300;
  std::vector<float> value(dims), velocity(dims);
  for (std::uint32_t first = 0; first < frames; first += kClipFrames) {
    Clip clip;
    clip.name = "clip" + std::to_string(parts.clips.size());
    clip.first_frame = first;
    clip.frame_count = std::min(kClipFrames, frames - first);
    for (std::uint32_t d = 0; d < dims; ++d) {
      value[d] = normal(rng);
      velocity[d] = 0.0f;
    }
    for (std::uint32_t f = first; f < first + clip.frame_count; ++f) {
      for (std::uint32_t d = 0; d < dims; ++d) {
        velocity[d] = 0.9f * velocity[d] + 0.05f * normal(rng);
        value[d] = 0.98f * value[d] + velocity[d];
        parts.features[std::size_t{f} * dims + d] = value[d];
      }
    }
    parts.clips.push_back(clip);
  }
  return std::move(Database::create(std::move(parts)).value());
}

// The rows: registry backends (mmvk/search/backends.hpp) by name, on the
// all-cores pool, plus fast-brute on a one-thread pool ("-1thread"): its CPU
// time is the single-core kernel throughput, which a loaded machine disturbs
// less than wall time.
struct Variant {
  const char* label;
  const char* backend;
  bool single_thread = false;
};
constexpr Variant kVariants[] = {
    {"reference", "reference"}, {"fast-brute", "fast-brute"}, {"fast-box", "fast-box"},
    {"fast-brute-1thread", "fast-brute", true}};

struct Fixture {
  const Database* db = nullptr;
  ThreadPool pool;  // all cores
  ThreadPool single{1};
  std::map<std::string, std::unique_ptr<SearchBackend>> backends;  // by Variant::label
};

Fixture& fixture(const std::string& label, const DatabaseProvider& provider) {
  static std::map<std::string, std::unique_ptr<Fixture>> fixtures;
  std::unique_ptr<Fixture>& f = fixtures[label];
  if (!f) {
    f = std::make_unique<Fixture>();
    f->db = provider();
    if (f->db) {
      const BackendRegistry registry = cpu_backends();
      for (const Variant& variant : kVariants) {
        const BackendSpec spec{.name = variant.backend, .pool = variant.single_thread ? &f->single : &f->pool};
        Result<std::unique_ptr<SearchBackend>> made = registry.make(spec, *f->db);
        if (made) {
          f->backends[variant.label] = std::move(made.value());
        } else {
          std::fprintf(stderr, "bench: %s: %s\n", variant.label, made.message().c_str());
        }
      }
    }
  }
  return *f;
}

void run(benchmark::State& state, const std::string& label, const DatabaseProvider& provider, QueryStream stream,
         const Variant& which) {
  Fixture& f = fixture(label, provider);
  if (!f.db || !f.backends.count(which.label)) {
    state.SkipWithError("database unavailable (see stderr)");
    return;
  }
  const std::size_t batch = static_cast<std::size_t>(state.range(0));
  const std::vector<float> queries = make_queries(*f.db, stream, batch);
  const QueryBatch query_batch{.features = queries, .params = {}, .size = batch};
  SearchBackend& backend = *f.backends.at(which.label);
  std::vector<Match> results(batch);
  backend.reset_stats();
  for (auto _ : state) {
    if (Status status = backend.search(query_batch, 1, results); !status) {
      state.SkipWithError(status.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(results.data());
  }
  const SearchStats stats = backend.stats();
  state.counters["queries/s"] = benchmark::Counter(double(batch), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["rows_fraction"] = stats.rows_fraction(f.db->frame_count());
  state.counters["row_dims/s"] =
      benchmark::Counter(double(stats.rows_evaluated) * f.db->dims(), benchmark::Counter::kIsRate);
  state.counters["frames"] = f.db->frame_count();
  if (const auto* fast = dynamic_cast<const FastSearch*>(&backend)) state.SetLabel(std::string(fast->kernel_name()));
}

}  // namespace

// Registers search/<label>/<stream>/<backend>/B:{1,64,1024}. The provider
// is called once, on first use; nullptr marks the data as unavailable.
void register_search_benchmarks(const std::string& label, DatabaseProvider provider, bool large) {
  for (QueryStream stream : {QueryStream::Continue, QueryStream::Transition, QueryStream::Uniform}) {
    for (const Variant& which : kVariants) {
      const std::string name = "search/" + label + "/" + std::string(query_stream_name(stream)) + "/" + which.label;
      auto* b = benchmark::RegisterBenchmark(name.c_str(), run, label, provider, stream, which);
      b->ArgName("B")->Arg(1)->Arg(64)->Arg(1024)->Unit(benchmark::kMicrosecond)->UseRealTime();
      if (std::string_view(which.backend) == "reference" && large) b->Iterations(1);
    }
  }
}

namespace {

const bool registered = [] {
  register_search_benchmarks("synthetic22k", [] {
    static const Database db = synthetic_motion_database(21791, 22);
    return &db;
  }, false);
  register_search_benchmarks("synthetic417k", [] {
    static const Database db = synthetic_motion_database(417000, 417);
    return &db;
  }, true);
  return true;
}();

}  // namespace
}  // namespace mmvk::bench
