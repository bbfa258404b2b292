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

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bench_data.hpp"
#include "mmvk/cluster_search.hpp"
#include "mmvk/cluster_table.hpp"
#include "mmvk/fast_search.hpp"
#include "mmvk/reference_search.hpp"
#include "mmvk/thread_pool.hpp"
#include "query_streams.hpp"

namespace mmvk::bench {
namespace {

enum class Backend { Reference, FastBrute, FastPruned, ClustersExact, Nprobe1, Nprobe4, Nprobe8, Nprobe16, Nprobe32, Nprobe64 };

const char* backend_name(Backend backend) {
  switch (backend) {
    case Backend::Reference: return "reference";
    case Backend::FastBrute: return "fast-brute";
    case Backend::FastPruned: return "fast-box";
    case Backend::ClustersExact: return "clusters";
    case Backend::Nprobe1: return "nprobe1";
    case Backend::Nprobe4: return "nprobe4";
    case Backend::Nprobe8: return "nprobe8";
    case Backend::Nprobe16: return "nprobe16";
    case Backend::Nprobe32: return "nprobe32";
    case Backend::Nprobe64: return "nprobe64";
  }
  return "?";
}

// Everything built for one database, once per process.
struct Fixture {
  const Database* db = nullptr;
  ThreadPool pool;  // all cores
  ClusterTable table;
  std::map<Backend, std::unique_ptr<SearchBackend>> backends;
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
        std::filesystem::path(MMVK_BENCH_WORK_DIR) / (std::string(data_set_name(set)) + suffix + ".mmkc");
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
      f->backends[Backend::Reference] = std::make_unique<ReferenceSearch>(*f->db);
      f->backends[Backend::FastBrute] = std::make_unique<FastSearch>(*f->db, f->pool, FastSearchOptions{.prune = false});
      f->backends[Backend::FastPruned] = std::make_unique<FastSearch>(*f->db, f->pool, FastSearchOptions{.prune = true});
      for (auto [backend, nprobe] :
           {std::pair{Backend::ClustersExact, 0u}, std::pair{Backend::Nprobe1, 1u}, std::pair{Backend::Nprobe4, 4u},
            std::pair{Backend::Nprobe8, 8u}, std::pair{Backend::Nprobe16, 16u}, std::pair{Backend::Nprobe32, 32u},
            std::pair{Backend::Nprobe64, 64u}}) {
        ClusterSearchOptions options{.nprobe = nprobe};
        // Tuning switches (MMVK_BENCH_PROBE_BY_BOUND=1, MMVK_BENCH_NO_SEED=1).
        options.probe_by_bound = std::getenv("MMVK_BENCH_PROBE_BY_BOUND") != nullptr;
        options.seed_nearest = std::getenv("MMVK_BENCH_NO_SEED") == nullptr;
        auto made = ClusterSearch::create(*f->db, f->table, f->pool, options);
        if (made) f->backends[backend] = std::move(made.value());
      }
    }
  }
  return fixtures.emplace(set, std::move(f)).first->second.get();
}

void run(benchmark::State& state, DataSet set, QueryStream stream, Backend which) {
  Fixture* f = fixture(set);
  if (!f->db || !f->backends.count(which)) {
    state.SkipWithError("database or backend unavailable (see stderr)");
    return;
  }
  const std::size_t batch = static_cast<std::size_t>(state.range(0));
  const std::vector<float> queries = make_queries(*f->db, stream, batch);
  const QueryBatch query_batch{.features = queries, .params = {}, .size = batch};
  std::vector<Match>& truth = f->truth[{stream, batch}];
  if (truth.empty()) {
    truth.resize(batch);
    if (!f->backends[Backend::FastBrute]->search(query_batch, 1, truth).ok()) {
      state.SkipWithError("exact search failed");
      return;
    }
  }
  SearchBackend& backend = *f->backends[which];
  std::vector<Match> results(batch);
  backend.reset_stats();
  for (auto _ : state) {
    if (Status status = backend.search(query_batch, 1, results); !status) {
      state.SkipWithError(status.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(results.data());
  }
  std::size_t hits = 0;
  for (std::size_t q = 0; q < batch; ++q) hits += results[q].frame == truth[q].frame;
  state.counters["queries/s"] = benchmark::Counter(double(batch), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["rows_fraction"] = backend.stats().rows_fraction(f->db->frame_count());
  state.counters["recall@1"] = double(hits) / double(batch);
  state.counters["frames"] = f->db->frame_count();
  if (const auto* clusters = dynamic_cast<const ClusterSearch*>(&backend)) {
    const double queries = double(backend.stats().queries);
    state.counters["clusters"] = clusters->cluster_count();
    state.counters["visited/q"] = double(clusters->counters().clusters_visited) / queries;
    state.counters["tiles_checked/q"] = double(clusters->counters().tiles_checked) / queries;
  }
}

const bool registered = [] {
  for (DataSet set : {DataSet::Locomotion, DataSet::Volume, DataSet::VolumeMirrored}) {
    for (QueryStream stream : {QueryStream::Transition, QueryStream::Continue, QueryStream::Uniform}) {
      for (Backend which : {Backend::Reference, Backend::FastBrute, Backend::FastPruned, Backend::ClustersExact,
                            Backend::Nprobe1, Backend::Nprobe4, Backend::Nprobe8, Backend::Nprobe16, Backend::Nprobe32,
                            Backend::Nprobe64}) {
        const std::string name = std::string("real/") + std::string(data_set_name(set)) + "/" +
                                 std::string(query_stream_name(stream)) + "/" + backend_name(which);
        auto* b = benchmark::RegisterBenchmark(name.c_str(), run, set, stream, which);
        b->ArgName("B")->Arg(1)->Arg(64)->Arg(1024)->Unit(benchmark::kMillisecond)->UseRealTime();
        if (which == Backend::Reference && set != DataSet::Locomotion) b->Iterations(1);
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace mmvk::bench
