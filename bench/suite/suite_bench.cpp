// The benchmark suite: mmvk's backends and the peers (bench/peers) on the
// same suite databases and query streams, one Google Benchmark cell per
//   suite/<dataset>/<schema>/<stream>/<method>/B:<batch>
// dataset  locomotion | volume104k | volume | volume-mirrored (bench_data.hpp)
// schema   default27 | wide60 (bench/schemas/wide60.json)
// stream   continue | transition | uniform (query_streams.hpp, seed 42)
// method   suite_methods.hpp
// batch    1 | 64 | 1024 | 8192 queries per search() call, k = 1
//
// Each (dataset, schema) draws a pool of 8192 queries per stream; iteration
// i searches queries [i*B, i*B + B) of the pool, wrapping, so small batches
// do not repeat one query. Databases, indexes and exact answers are built
// on the first cell that needs them, so a filter only pays for what it
// selects; cells run (dataset, schema) by (dataset, schema) and method by
// method, and only the current ones are kept in memory. Counters (README.md in bench/peers):
// us_per_query, queries_per_s, rows_fraction, recall1, recall10, near_ties,
// recall_queries, db_bytes, index_bytes, device_bytes, build_s,
// kernel_us_per_query, N, dims.
//
//   build/bench/mmvk_suite --benchmark_filter='suite/locomotion/default27/.*/B:(1|1024)'
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "peer.hpp"
#include "query_streams.hpp"
#include "suite_methods.hpp"
#include "suite_vulkan.hpp"

namespace mmvk::bench {
namespace {

constexpr std::size_t kPoolQueries = 8192;
constexpr std::size_t kRecallQueries = 1024;  // the first queries of each pool
constexpr std::uint32_t kRecallK = 10;
constexpr DataSet kSets[] = {DataSet::Locomotion, DataSet::Volume104k, DataSet::Volume, DataSet::VolumeMirrored};
constexpr SuiteSchema kSchemas[] = {SuiteSchema::Default27, SuiteSchema::Wide60};
constexpr QueryStream kStreams[] = {QueryStream::Continue, QueryStream::Transition, QueryStream::Uniform};
constexpr std::int64_t kBatches[] = {1, 64, 1024, 8192};

struct Recall {
  double at1 = 0.0, at10 = 0.0;
  // Queries whose top 1 differs from the exact one only by a float near-tie
  // (peers::is_float_near_tie), and the queries measured (0: exact by
  // construction, not measured).
  double near_ties = 0.0, queries = 0.0;
};

// Everything the cells of one (dataset, schema) share. Cells run in
// registration order, method by method (see `registered`), so the fixture
// keeps one method alive at a time: the 834k-frame sets hold hundreds of MB
// per backend (tiled copies, FAISS's copies, lavapipe's device memory).
struct Fixture {
  const Database* db = nullptr;
  std::unique_ptr<SuiteMethodFactory> factory;
  std::map<QueryStream, std::vector<float>> queries;
  std::map<QueryStream, std::vector<Match>> truth;  // [kRecallQueries x kRecallK]
  std::unique_ptr<SuiteMethod> oracle;              // fast-brute, for the truth
  std::string current_name;
  std::unique_ptr<SuiteMethod> current;
  std::map<std::string, std::string> method_errors;
  std::map<std::pair<QueryStream, std::string>, Recall> recall;

  const std::vector<float>& pool(QueryStream stream) {
    std::vector<float>& q = queries[stream];
    if (q.empty()) q = make_queries(*db, stream, kPoolQueries, 42);
    return q;
  }

  // nullptr after setting `error`.
  SuiteMethod* method(const std::string& name, std::string& error) {
    if (current && current_name == name) return current.get();
    if (auto failed = method_errors.find(name); failed != method_errors.end()) {
      error = failed->second;
      return nullptr;
    }
    current.reset();  // before making the next one: one method's memory at a time
    std::fprintf(stderr, "suite: making %s over %u frames x %u dims\n", name.c_str(), db->frame_count(), db->dims());
    Result<SuiteMethod> made = factory->make(name);
    if (!made) {
      error = method_errors[name] = made.message();
      std::fprintf(stderr, "suite: %s: %s\n", name.c_str(), error.c_str());
      return nullptr;
    }
    current_name = name;
    current = std::make_unique<SuiteMethod>(std::move(made.value()));
    return current.get();
  }

  Status search(SearchBackend& backend, QueryStream stream, std::size_t first, std::size_t count, std::uint32_t k,
                std::span<Match> out) {
    const std::vector<float>& q = pool(stream);
    const QueryBatch batch{.features = std::span<const float>(q).subspan(first * db->dims(), count * db->dims()),
                           .params = {},
                           .size = count};
    return backend.search(batch, k, out);
  }

  // recall@1 and recall@10 of `name` against the exact top 10 (fast-brute,
  // which returns the reference's frames and cost bits) over the first
  // kRecallQueries queries of the stream.
  Result<Recall> measure_recall(const std::string& name, SuiteMethod& method, QueryStream stream) {
    if (method.exact) return Recall{.at1 = 1.0, .at10 = 1.0};
    if (auto found = recall.find({stream, name}); found != recall.end()) return found->second;
    std::vector<Match>& exact = truth[stream];
    if (exact.empty()) {
      if (!oracle) {
        Result<SuiteMethod> brute = factory->make("fast-brute");
        if (!brute) return brute.error();
        oracle = std::make_unique<SuiteMethod>(std::move(brute.value()));
      }
      exact.resize(kRecallQueries * kRecallK);
      MMVK_TRY(search(*oracle->backend, stream, 0, kRecallQueries, kRecallK, exact));
    }
    std::vector<Match> found(kRecallQueries * kRecallK);
    MMVK_TRY(search(*method.backend, stream, 0, kRecallQueries, kRecallK, found));
    Recall r;
    for (std::size_t q = 0; q < kRecallQueries; ++q) {
      const std::span<const Match> want(&exact[q * kRecallK], kRecallK), got(&found[q * kRecallK], kRecallK);
      r.at1 += got[0].frame == want[0].frame;
      if (got[0].frame != want[0].frame) {
        const std::span<const float> query = std::span(pool(stream)).subspan(q * db->dims(), db->dims());
        r.near_ties += peers::is_float_near_tie(*db, query, want[0], got[0].frame);
      }
      for (const Match& m : got) {
        r.at10 += std::any_of(want.begin(), want.end(), [&](const Match& w) { return w.frame == m.frame; });
      }
    }
    r.queries = double(kRecallQueries);
    r.at1 /= double(kRecallQueries);
    r.at10 /= double(kRecallQueries * kRecallK);
    return recall[{stream, name}] = r;
  }
};

struct Suite {
  Suite() { prepare_vulkan_context(); }  // first, so it outlives the fixtures' Vulkan backends
  ThreadPool pool;  // every core, shared by the threaded backends
  // One (dataset, schema) at a time, as cells run in that order.
  std::pair<DataSet, SuiteSchema> key;
  std::unique_ptr<Fixture> current;

  Fixture* fixture(DataSet set, SuiteSchema schema) {
    if (current && key != std::make_pair(set, schema)) current.reset();
    key = {set, schema};
    std::unique_ptr<Fixture>& f = current;
    if (!f) {
      f = std::make_unique<Fixture>();
      f->db = suite_database(set, schema);
      if (f->db) {
        const std::string stem =
            std::string(data_set_name(set)) + "-" + std::string(suite_schema_name(schema)) + "-all";
        f->factory = std::make_unique<SuiteMethodFactory>(*f->db, pool, stem);
      }
    }
    return f->db ? f.get() : nullptr;
  }
};

Suite& suite() {
  static Suite s;
  return s;
}

void run_cell(benchmark::State& state, DataSet set, SuiteSchema schema, QueryStream stream, const std::string& name) {
  Fixture* f = suite().fixture(set, schema);
  if (f == nullptr) {
    state.SkipWithError("the database is unavailable (see stderr)");
    return;
  }
  std::string error;
  SuiteMethod* method = f->method(name, error);
  if (method == nullptr) {
    state.SkipWithError(error.c_str());
    return;
  }
  Result<Recall> recall = f->measure_recall(name, *method, stream);
  if (!recall) {
    state.SkipWithError(recall.message().c_str());
    return;
  }
  const std::size_t batch = static_cast<std::size_t>(state.range(0));
  std::vector<Match> out(batch);
  SearchBackend& backend = *method->backend;
  backend.reset_stats();
  double kernel_s = 0.0;
  std::size_t first = 0, searched = 0;
  const auto start = std::chrono::steady_clock::now();
  for (auto _ : state) {
    if (Status status = f->search(backend, stream, first, batch, 1, out); !status) {
      state.SkipWithError(status.message().c_str());
      return;
    }
    benchmark::DoNotOptimize(out.data());
    if (method->vulkan != nullptr) kernel_s += last_kernel_seconds(*method->vulkan);
    first = (first + batch) % kPoolQueries;
    searched += batch;
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const Database& db = *f->db;
  const double queries = double(std::max<std::size_t>(searched, 1));
  state.counters["us_per_query"] = elapsed * 1e6 / queries;
  state.counters["queries_per_s"] = queries / elapsed;
  const SearchStats stats = backend.stats();
  state.counters["rows_fraction"] =
      stats.queries == 0 ? std::numeric_limits<double>::quiet_NaN() : stats.rows_fraction(db.frame_count());
  state.counters["recall1"] = recall->at1;
  state.counters["recall10"] = recall->at10;
  state.counters["near_ties"] = recall->near_ties;
  state.counters["recall_queries"] = recall->queries;
  state.counters["db_bytes"] = double(db.features().size() * sizeof(float));
  state.counters["index_bytes"] = method->index_bytes;
  state.counters["device_bytes"] = method->device_bytes;
  state.counters["build_s"] = method->build_s;
  state.counters["kernel_us_per_query"] = kernel_s * 1e6 / queries;
  state.counters["N"] = db.frame_count();
  state.counters["dims"] = db.dims();
  if (!method->settings.empty()) state.SetLabel(method->settings);
}

// Registered dataset, schema, method, stream, batch: the order the cells
// run in, so each method is made once per (dataset, schema) and dropped
// before the next (Fixture). The names keep the agreed order.
const bool registered = [] {
  for (const DataSet set : kSets) {
    for (const SuiteSchema schema : kSchemas) {
      for (const std::string& method : suite_method_names()) {
        for (const QueryStream stream : kStreams) {
          const std::string name = "suite/" + std::string(data_set_name(set)) + "/" +
                                   std::string(suite_schema_name(schema)) + "/" + std::string(query_stream_name(stream)) +
                                   "/" + method;
          benchmark::RegisterBenchmark(name.c_str(), run_cell, set, schema, stream, method)
              ->ArgName("B")
              ->Args({kBatches[0]})
              ->Args({kBatches[1]})
              ->Args({kBatches[2]})
              ->Args({kBatches[3]})
              ->Unit(benchmark::kMicrosecond)
              ->UseRealTime();
        }
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace mmvk::bench
