// The Vulkan cluster backends (vulkan-clusters, vulkan-nprobe 4/16) beside
// vulkan-brute, the CPU clusters and fast-brute, on the
// real databases of bench_data.hpp, with the cluster table trained by
// train_cluster_table(db, KMeansParams{}) (round(sqrt(N)) clusters).
//
// Counters: queries/s (kIsRate, end to end: submit to results in host
// memory), kernel_ms (GPU time of the last batch from timestamps),
// device_MiB (VulkanSearch::device_bytes(): all it allocated), rows
// (fraction of the frames evaluated per query), recall@1 (the frame found
// equals FastSearch brute force's exact frame; 1 for exact backends).
//
//   build/bench/mmvk_bench --benchmark_filter='vclusters/locomotion/'
#include <benchmark/benchmark.h>

#if defined(MMVK_HAS_VULKAN)

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "backends/host_backends.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"
#include "query_streams.hpp"

namespace mmvk::bench {
namespace {

constexpr std::size_t kQueries = 1024;
constexpr QueryStream kStreams[] = {QueryStream::Continue, QueryStream::Transition, QueryStream::Uniform};
constexpr DataSet kSets[] = {DataSet::Locomotion, DataSet::Volume, DataSet::VolumeMirrored};
constexpr std::uint32_t kBatches[] = {1, 64, 1024};
// The rows: registry backends (mmvk/search/backends.hpp) by name, with the nprobe
// of the *-nprobe ones in the label.
struct Variant {
  const char* label;
  const char* backend;
  std::uint32_t nprobe = 4;
  // The CPU backends' instruction set: fast-brute-avx2 runs the 256-bit
  // kernels, the vector width lavapipe's lanes have (shared/LAVAPIPE.md),
  // to tell the width's share of the Vulkan/CPU gap from the kernel's.
  CpuKernels kernels = CpuKernels::Widest;
  // vulkan-brute-t32: the brute-force scan's 32-query tile (max_tile 32;
  // the registry's default is 16, whose first compile is shorter).
  std::uint32_t max_tile = 16;
};
constexpr Variant kVariants[] = {{"fast-brute", "fast-brute"},
                                 {"fast-brute-avx2", "fast-brute", 4, CpuKernels::Avx2},
                                 {"clusters", "clusters"},
                                 {"vulkan-brute", "vulkan-brute"},
                                 {"vulkan-brute-t32", "vulkan-brute", 4, CpuKernels::Widest, 32},
                                 {"vulkan-clusters", "vulkan-clusters"},
                                 {"vulkan-nprobe4", "vulkan-nprobe", 4}, {"vulkan-nprobe16", "vulkan-nprobe", 16}};

// The benchmark's backends, made where the hosts make theirs, on one
// Vulkan context for every row (a process-wide object is fine in a
// benchmark's main program, never in the library).
crowd::HostBackends& host_backends() {
  static crowd::HostBackends backends;
  return backends;
}

// One database's table, backends, query streams and exact answers; the
// backends are created on first use (lavapipe compiles at creation).
struct Setup {
  const Database* db = nullptr;
  ThreadPool pool;
  ClusterTable table;
  std::map<std::string, std::unique_ptr<SearchBackend>> backends;
  std::map<QueryStream, std::vector<float>> queries;
  std::map<QueryStream, std::vector<std::uint32_t>> truth;
};

Setup* setup_for(DataSet set) {
  // Statics are destroyed in reverse order of construction: creating the
  // backends' owner first makes its context outlive the Vulkan backends in
  // the cache (the other order aborted at exit).
  (void)host_backends();
  static std::map<DataSet, std::unique_ptr<Setup>> cache;
  std::unique_ptr<Setup>& slot = cache[set];
  if (slot) return slot->db ? slot.get() : nullptr;
  slot = std::make_unique<Setup>();
  Setup& s = *slot;
  const Database* db = database(set);
  if (db == nullptr) return nullptr;
  Result<ClusterTable> table = train_cluster_table(*db, KMeansParams{}, s.pool);
  if (!table.ok()) {
    std::fprintf(stderr, "vulkan_cluster_bench: %s\n", table.message().c_str());
    return nullptr;
  }
  s.table = std::move(table).value();
  Result<std::unique_ptr<SearchBackend>> exact = make_backend(BackendSpec{.name = "fast-brute", .pool = &s.pool}, *db);
  if (!exact.ok()) return nullptr;
  for (const QueryStream stream : kStreams) {
    s.queries[stream] = make_queries(*db, stream, kQueries);
    std::vector<Match> out(kQueries);
    if (!(*exact)->search({s.queries[stream], {}, kQueries}, 1, out).ok()) return nullptr;
    for (const Match& m : out) s.truth[stream].push_back(m.frame);
  }
  s.db = db;
  return &s;
}

Result<std::unique_ptr<SearchBackend>> make_variant(Setup& s, const Variant& variant) {
  BackendSpec spec{.name = variant.backend, .pool = &s.pool, .clusters = &s.table};
  spec.nprobe = variant.nprobe;
  spec.fast.kernels = variant.kernels;
  crowd::DeviceSearchLimits limits;
  limits.max_batch = kQueries;
  limits.max_k = 1;
  limits.max_tile = variant.max_tile;
  return host_backends().make(spec, *s.db, limits);
}

void run(benchmark::State& state, DataSet set, QueryStream stream, const Variant& variant, std::uint32_t batch) {
  Setup* s = setup_for(set);
  if (s == nullptr) {
    state.SkipWithError("database unavailable");
    return;
  }
  std::unique_ptr<SearchBackend>& backend = s->backends[variant.label];
  if (!backend) {
    Result<std::unique_ptr<SearchBackend>> made = make_variant(*s, variant);
    if (!made.ok()) {
      state.SkipWithError(made.message().c_str());
      return;
    }
    backend = std::move(made).value();
  }
  const std::vector<float>& all = s->queries.at(stream);
  const std::vector<std::uint32_t>& truth = s->truth.at(stream);
  const std::uint32_t dims = s->db->dims();
  std::vector<Match> out(batch);
  backend->reset_stats();
  std::size_t offset = 0;
  std::uint64_t hits = 0;
  std::uint64_t total = 0;
  for (auto _ : state) {
    const QueryBatch q{std::span<const float>(all).subspan(offset * dims, std::size_t{batch} * dims), {}, batch};
    if (!backend->search(q, 1, out).ok()) {
      state.SkipWithError("search failed");
      return;
    }
    for (std::uint32_t i = 0; i < batch; ++i) hits += out[i].frame == truth[offset + i] ? 1 : 0;
    total += batch;
    offset = (offset + batch) % kQueries;
  }
  state.counters["queries/s"] = benchmark::Counter(double(total), benchmark::Counter::kIsRate);
  state.counters["rows"] = backend->stats().rows_fraction(s->db->frame_count());
  state.counters["recall@1"] = total == 0 ? 0.0 : double(hits) / double(total);
  if (auto* gpu = dynamic_cast<vulkan::VulkanSearch*>(backend.get()); gpu != nullptr) {
    state.counters["kernel_ms"] = gpu->last_kernel_seconds().value_or(0.0) * 1e3;
    state.counters["device_MiB"] = double(gpu->device_bytes()) / double(1 << 20);
  }
}

const bool registered = [] {
  for (const DataSet set : kSets) {
    for (const QueryStream stream : kStreams) {
      for (const Variant& variant : kVariants) {
        for (const std::uint32_t batch : kBatches) {
          const std::string name = "vclusters/" + std::string(data_set_name(set)) + "/" +
                                   std::string(query_stream_name(stream)) + "/" + variant.label + "/B:" +
                                   std::to_string(batch);
          benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
            run(state, set, stream, variant, batch);
          })->UseRealTime()->MinTime(0.3);
        }
      }
    }
  }
  return true;
}();

}  // namespace
}  // namespace mmvk::bench

#endif  // MMVK_HAS_VULKAN
