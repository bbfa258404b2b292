// Search on the real motion capture: every CPU backend on the Bandai
// locomotion (~22k frames), volume (~417k) and mirrored volume (~834k)
// databases, for the three query streams and batch sizes 1, 64, 1024.
// Counters: queries/s, the fraction of rows evaluated, and recall@1 against
// the exact answer (1.0 for exact backends, by construction and by test).
//
//   build/bench/mmvk_bench --benchmark_filter='real/locomotion/.*'
//
// The reference runs one iteration at the large sizes (it takes seconds).
#include <benchmark/benchmark.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "bench_data.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/search/cluster_search.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "query_streams.hpp"

namespace mmvk::bench {
namespace {

// The rows: a registry backend (mmvk/search/backends.hpp) and, for the nprobe
// rows, the nprobe; the row's label is the backend's name plus the nprobe.
struct Variant {
  std::string label;
  std::string backend;
  std::uint32_t nprobe = 0;
  // clusters-per-query: the grouped walk and the span boxes off (the
  // one-query walk the grouping replaced), for before/after in one run.
  bool per_query = false;
  // The instruction set of the tile kernels: the *-avx2 rows hold the
  // 256-bit kernels to the 256-bit plain loop (plain-loop-avx2) on a CPU
  // that also has AVX-512F.
  CpuKernels kernels = CpuKernels::Widest;
  // clusters-float: ClusterSearchOptions::half_filter off (every visited
  // row evaluated from the float tiles), for before/after in one run.
  bool half_filter = true;
};

const std::vector<Variant>& variants() {
  static const std::vector<Variant> all = [] {
    std::vector<Variant> v = {{"reference", "reference"}, {"fast-brute", "fast-brute"}, {"fast-box", "fast-box"},
                              {"clusters", "clusters"}, {"clusters-per-query", "clusters", 0, true},
                              {"fast-brute-avx2", "fast-brute", 0, false, CpuKernels::Avx2},
                              {"clusters-avx2", "clusters", 0, false, CpuKernels::Avx2},
                              {"clusters-float", "clusters", 0, false, CpuKernels::Widest, false}};
    for (const std::uint32_t nprobe : {1u, 4u, 8u, 16u, 32u, 64u}) {
      v.push_back({"clusters-nprobe" + std::to_string(nprobe), "clusters-nprobe", nprobe});
    }
    return v;
  }();
  return all;
}

// The pool's spin before its threads sleep: MMVK_BENCH_SPIN_US (tuning; 0
// measures the pool as it was before it spun), else the library default.
unsigned pool_spin_us() {
  const char* spin = std::getenv("MMVK_BENCH_SPIN_US");
  return spin == nullptr ? ThreadPool::kDefaultSpinMicroseconds : static_cast<unsigned>(std::strtoul(spin, nullptr, 10));
}

// Everything built for one database, once per process.
struct Fixture {
  const Database* db = nullptr;
  ThreadPool pool{0, pool_spin_us()};  // all cores
  ClusterTable table;
  std::map<std::string, std::unique_ptr<SearchBackend>> backends;  // by Variant::label
  // Exact top-1 per (stream, batch), for recall.
  std::map<std::pair<QueryStream, std::size_t>, std::vector<Match>> truth;
};

Fixture* fixture(DataSet set) {
  static std::map<DataSet, std::unique_ptr<Fixture>> fixtures;
  auto found = fixtures.find(set);
  if (found != fixtures.end()) return found->second.get();
  auto f = std::make_unique<Fixture>();
  f->db = database(set);
  if (f->db) {
    // MMVK_BENCH_CLUSTERS=n trains n clusters instead of the default (for
    // tuning); each count has its own cache file.
    KMeansParams params;
    const char* clusters = std::getenv("MMVK_BENCH_CLUSTERS");
    if (clusters != nullptr) params.clusters = static_cast<std::uint32_t>(std::strtoul(clusters, nullptr, 10));
    const std::string suffix = params.clusters == 0 ? "" : "-c" + std::to_string(params.clusters);
    const std::filesystem::path cache =
        bench_work_dir() / (std::string(data_set_name(set)) + suffix + ".mmkc");
    Result<ClusterTable> table = load_cluster_table(cache);
    if (!table || !validate_cluster_table(*table, *f->db).ok()) {
      table = train_cluster_table(*f->db, params, f->pool);
      if (table) (void)save_cluster_table(*table, cache);
    }
    if (!table) {
      std::fprintf(stderr, "bench: %s\n", table.message().c_str());
      f->db = nullptr;
    } else {
      f->table = std::move(table.value());
      const BackendRegistry registry = cpu_backends();
      for (const Variant& variant : variants()) {
        BackendSpec spec{.name = variant.backend, .pool = &f->pool, .clusters = &f->table};
        spec.nprobe = variant.nprobe;
        spec.fast.kernels = variant.kernels;
        spec.cluster.kernels = variant.kernels;
        spec.cluster.half_filter = variant.half_filter;
        // Tuning switch (MMVK_BENCH_NO_SEED=1).
        spec.cluster.seed_nearest = std::getenv("MMVK_BENCH_NO_SEED") == nullptr;
        if (variant.per_query) {
          spec.cluster.batch_by_cluster = false;
          spec.cluster.span_bound = false;
        }
        Result<std::unique_ptr<SearchBackend>> made = registry.make(spec, *f->db);
        if (made) {
          f->backends[variant.label] = std::move(made.value());
        } else {
          std::fprintf(stderr, "bench: %s: %s\n", variant.label.c_str(), made.message().c_str());
        }
      }
    }
  }
  return fixtures.emplace(set, std::move(f)).first->second.get();
}

// How the batch's queries are searched: at once; one at a time (B = 1
// calls back to back), so the per-query figures compare with the batched
// row of the same B; or one at a time 1 ms apart, as a game issuing one
// query per tick would (wall_us/q then times the calls only; the pool's
// threads have gone to sleep between them).
enum class Calls { Batch, Singly, Paced };

void run(benchmark::State& state, DataSet set, QueryStream stream, const std::string& which, Calls calls) {
  Fixture* f = fixture(set);
  if (!f->db || !f->backends.count(which) || !f->backends.count("fast-brute")) {
    state.SkipWithError("database or backend unavailable (see stderr)");
    return;
  }
  const std::size_t batch = static_cast<std::size_t>(state.range(0));
  const std::vector<float> queries = make_queries(*f->db, stream, batch);
  const QueryBatch query_batch{.features = queries, .params = {}, .size = batch};
  std::vector<Match>& truth = f->truth[{stream, batch}];
  if (truth.empty()) {
    truth.resize(batch);
    if (!f->backends.at("fast-brute")->search(query_batch, 1, truth).ok()) {
      state.SkipWithError("exact search failed");
      return;
    }
  }
  SearchBackend& backend = *f->backends.at(which);
  std::vector<Match> results(batch);
  backend.reset_stats();
  const double cpu_start = process_cpu_seconds();
  const auto wall_start = std::chrono::steady_clock::now();
  double paced_seconds = 0.0;  // Calls::Paced: inside the calls
  for (auto _ : state) {
    if (calls != Calls::Batch) {
      for (std::size_t q = 0; q < batch; ++q) {
        const std::size_t dims = f->db->dims();
        const QueryBatch one{.features = std::span<const float>(queries).subspan(q * dims, dims), .params = {}, .size = 1};
        if (calls == Calls::Paced) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        const auto call_start = std::chrono::steady_clock::now();
        if (Status status = backend.search(one, 1, std::span<Match>(results).subspan(q, 1)); !status) {
          state.SkipWithError(status.message().c_str());
          return;
        }
        paced_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - call_start).count();
      }
    } else if (Status status = backend.search(query_batch, 1, results); !status) {
      state.SkipWithError(status.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(results.data());
  }
  const double wall_seconds = calls == Calls::Paced
                                  ? paced_seconds
                                  : std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const double cpu_seconds = process_cpu_seconds() - cpu_start;
  std::size_t hits = 0;
  for (std::size_t q = 0; q < batch; ++q) hits += results[q].frame == truth[q].frame;
  state.counters["queries/s"] = benchmark::Counter(double(batch), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["rows_fraction"] = backend.stats().rows_fraction(f->db->frame_count());
  state.counters["recall@1"] = double(hits) / double(batch);
  state.counters["frames"] = f->db->frame_count();
  // CPU time of every thread of the process per query: steadier than wall
  // time on a loaded machine (the pool's threads sleep when idle).
  state.counters["cpu_us/q"] = cpu_seconds * 1e6 / (double(state.iterations()) * double(batch));
  state.counters["wall_us/q"] = wall_seconds * 1e6 / (double(state.iterations()) * double(batch));
  if (const auto* clusters = dynamic_cast<const ClusterSearch*>(&backend)) {
    const double queries = double(backend.stats().queries);
    state.counters["clusters"] = clusters->cluster_count();
    state.counters["visited/q"] = double(clusters->counters().clusters_visited) / queries;
    state.counters["tiles_checked/q"] = double(clusters->counters().tiles_checked) / queries;
    state.counters["tiles_filtered/q"] = double(clusters->counters().tiles_filtered) / queries;
    state.counters["passed/q"] = double(clusters->counters().rows_rechecked) / queries;
    state.counters["exact/q"] = double(clusters->counters().rows_exact) / queries;
    state.counters["rows/q"] = double(backend.stats().rows_evaluated) / queries;
  }
}

const bool registered = [] {
  for (DataSet set : {DataSet::Locomotion, DataSet::Volume, DataSet::VolumeMirrored}) {
    for (QueryStream stream : {QueryStream::Transition, QueryStream::Continue, QueryStream::Uniform}) {
      for (const Variant& variant : variants()) {
        const std::string name = std::string("real/") + std::string(data_set_name(set)) + "/" +
                                 std::string(query_stream_name(stream)) + "/" + variant.label;
        auto* b = benchmark::RegisterBenchmark(name.c_str(), run, set, stream, variant.label, Calls::Batch);
        b->ArgName("B")->Arg(1)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
        if (variant.backend == "reference" && set != DataSet::Locomotion) b->Iterations(1);
        if (variant.label == "clusters" || variant.label == "clusters-per-query") {
          // B = 1 latency over the same queries as the B = 1024 row.
          auto* singly =
              benchmark::RegisterBenchmark((name + "-singly").c_str(), run, set, stream, variant.label, Calls::Singly);
          singly->ArgName("B")->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
          // The same 1 ms apart: one pass takes over a second, so once.
          auto* paced =
              benchmark::RegisterBenchmark((name + "-paced").c_str(), run, set, stream, variant.label, Calls::Paced);
          paced->ArgName("B")->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
        }
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace mmvk::bench
