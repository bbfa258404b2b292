// Vulkan brute force vs the CPU reference vs the fast CPU brute force, on
// synthetic databases (random-walk clips, the default schema's 27-d channel
// layout), registered over ArgsProduct({frames}, {dims}, {batch}). Every
// figure is a ratio to a CPU backend measured in the same run.
//
// Counters: queries/s (kIsRate), G row*dims/s (frames x dims x queries per
// second), and for Vulkan the kernel time from timestamp queries
// (BM_VulkanKernel uses it as manual time) next to the end-to-end wall time
// from submit to results in host memory (BM_VulkanEndToEnd).
//
// The BM_Real* group runs the same comparison on the real databases of
// bench_data.hpp (Bandai locomotion ~22k frames, volume ~417k, mirrored
// ~834k; built once and cached in the build tree).
//
//   build-vulkan/bench/mmvk_bench --benchmark_filter='Vulkan|FastBrute|Reference'
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench_data.hpp"
#include "backends/host_backends.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/common/thread_pool.hpp"

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/vulkan_search.hpp"
#endif

namespace mmvk::bench {
namespace {

constexpr std::uint32_t kClipFrames = 600;

// A synthetic database of `frames` rows: random-walk clips (like motion, so
// neighbouring rows are close) over channels of 3 and 6 dims.
Database make_synthetic(std::uint32_t frames, std::uint32_t dims) {
  std::mt19937_64 rng(20261122);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  DatabaseParts parts;
  std::uint32_t left = dims;
  for (int c = 0; left > 0; ++c) {
    FeatureChannel channel;
    channel.name = "channel" + std::to_string(c);
    channel.kind = ChannelKind::Custom;
    channel.custom_dims = std::min(left, c < 5 ? 3u : 6u);
    left -= channel.custom_dims;
    parts.schema.channels.push_back(channel);
  }
  parts.fps = 30.0f;
  parts.normalization.assign(dims, DimNormalization{});
  parts.frame_flags.assign(frames, 0);
  parts.features.resize(std::size_t{frames} * dims);
  std::vector<float> value(dims);
  for (std::uint32_t first = 0; first < frames; first += kClipFrames) {
    Clip clip;
    clip.name = "clip" + std::to_string(first / kClipFrames);
    clip.first_frame = first;
    clip.frame_count = std::min(kClipFrames, frames - first);
    for (float& v : value) v = normal(rng);
    for (std::uint32_t f = first; f < first + clip.frame_count; ++f) {
      for (std::uint32_t d = 0; d < dims; ++d) {
        value[d] += 0.1f * normal(rng);
        parts.features[std::size_t{f} * dims + d] = value[d];
      }
    }
    parts.clips.push_back(clip);
  }
  return std::move(Database::create(std::move(parts))).value();
}

const Database& database_for(std::uint32_t frames, std::uint32_t dims) {
  static std::map<std::pair<std::uint32_t, std::uint32_t>, std::unique_ptr<Database>> cache;
  std::unique_ptr<Database>& db = cache[{frames, dims}];
  if (!db) db = std::make_unique<Database>(make_synthetic(frames, dims));
  return *db;
}

// Queries near database rows ("continue"-like), fixed seed.
std::vector<float> make_queries(const Database& db, std::size_t count) {
  std::mt19937_64 rng(7);
  std::normal_distribution<float> normal(0.0f, 0.2f);
  std::uniform_int_distribution<std::uint32_t> frame(0, db.frame_count() - 1);
  std::vector<float> queries(count * db.dims());
  for (std::size_t q = 0; q < count; ++q) {
    const std::span<const float> row = db.row(frame(rng));
    for (std::uint32_t d = 0; d < db.dims(); ++d) queries[q * db.dims() + d] = row[d] + normal(rng);
  }
  return queries;
}

// CPU time of the whole process (lavapipe's worker threads included): on a
// shared, loaded machine, work per CPU-second is steadier than wall time.
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void set_counters(benchmark::State& state, const Database& db, std::size_t batch) {
  const double queries = double(state.iterations()) * double(batch);
  state.counters["queries/s"] = benchmark::Counter(queries, benchmark::Counter::kIsRate);
  state.counters["G_rowdims/s"] =
      benchmark::Counter(queries * db.frame_count() * db.dims() * 1e-9, benchmark::Counter::kIsRate);
}

void run_cpu(benchmark::State& state, SearchBackend& backend, std::size_t batch) {
  const Database& db = backend.database();
  const std::vector<float> queries = make_queries(db, batch);
  std::vector<Match> out(batch);
  const double cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    const Status status = backend.search(QueryBatch{queries, {}, batch}, 1, out);
    if (!status) state.SkipWithError(status.message().c_str());
    benchmark::DoNotOptimize(out.data());
  }
  const double cpu_seconds = process_cpu_seconds() - cpu_start;
  set_counters(state, db, batch);
  state.counters["G_rowdims_per_cpu_s"] =
      double(state.iterations()) * double(batch) * db.frame_count() * db.dims() * 1e-9 / cpu_seconds;
  state.counters["rows_fraction"] = backend.stats().rows_fraction(db.frame_count());
}

void run_cpu_backend(benchmark::State& state, const BackendSpec& spec, const Database& db, std::size_t batch) {
  Result<std::unique_ptr<SearchBackend>> backend = make_backend(spec, db);
  if (!backend) {
    state.SkipWithError(backend.message().c_str());
    return;
  }
  run_cpu(state, **backend, batch);
}

void BM_Reference(benchmark::State& state) {
  const Database& db = database_for(std::uint32_t(state.range(0)), std::uint32_t(state.range(1)));
  run_cpu_backend(state, BackendSpec{.name = "reference"}, db, std::size_t(state.range(2)));
}

void BM_FastBrute(benchmark::State& state) {
  const Database& db = database_for(std::uint32_t(state.range(0)), std::uint32_t(state.range(1)));
  ThreadPool pool(2);
  run_cpu_backend(state, BackendSpec{.name = "fast-brute", .pool = &pool}, db, std::size_t(state.range(2)));
}

#if defined(MMVK_HAS_VULKAN)
// The benchmark's backends, made where the hosts make theirs, on one
// Vulkan context for every row (a process-wide object is fine in a
// benchmark's main program, never in the library).
crowd::HostBackends& host_backends() {
  static crowd::HostBackends backends;
  return backends;
}

// kernel_time: report the timestamp-query kernel time as the iteration time
// (UseManualTime); else wall time from submit to results in host memory.
void run_vulkan(benchmark::State& state, const Database& db, std::size_t batch, std::uint32_t max_tile,
                bool kernel_time) {
  crowd::DeviceSearchLimits limits;
  limits.max_batch = std::uint32_t(batch);
  limits.max_k = 1;
  limits.max_tile = max_tile;
  Result<std::unique_ptr<SearchBackend>> made = host_backends().make(BackendSpec{.name = "vulkan-brute"}, db, limits);
  if (!made) {
    state.SkipWithError(made.message().c_str());
    return;
  }
  // The registry makes a VulkanSearch; its kernel timestamps are Vulkan's own.
  auto* search = static_cast<vulkan::VulkanSearch*>(made->get());
  const std::vector<float> queries = make_queries(db, batch);
  std::vector<Match> out(batch);
  double kernel_seconds = 0.0;
  const double cpu_start = process_cpu_seconds();
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    const Status status = search->search(QueryBatch{queries, {}, batch}, 1, out);
    const auto end = std::chrono::steady_clock::now();
    if (!status) {
      state.SkipWithError(status.message().c_str());
      break;
    }
    const double kernel = search->last_kernel_seconds().value_or(std::chrono::duration<double>(end - start).count());
    kernel_seconds += kernel;
    if (kernel_time) state.SetIterationTime(kernel);
  }
  const double cpu_seconds = process_cpu_seconds() - cpu_start;
  set_counters(state, db, batch);
  state.counters["G_rowdims_per_cpu_s"] =
      double(state.iterations()) * double(batch) * db.frame_count() * db.dims() * 1e-9 / cpu_seconds;
  state.counters["kernel_ms"] = benchmark::Counter(kernel_seconds * 1e3 / double(std::max<std::int64_t>(state.iterations(), 1)));
  state.counters["rows_fraction"] = search->stats().rows_fraction(db.frame_count());
}

void run_vulkan_synthetic(benchmark::State& state, bool kernel_time) {
  const Database& db = database_for(std::uint32_t(state.range(0)), std::uint32_t(state.range(1)));
  run_vulkan(state, db, std::size_t(state.range(2)), std::uint32_t(state.range(3)), kernel_time);
}

void BM_VulkanEndToEnd(benchmark::State& state) { run_vulkan_synthetic(state, false); }
void BM_VulkanKernel(benchmark::State& state) { run_vulkan_synthetic(state, true); }

void BM_RealVulkan(benchmark::State& state) {
  const Database* db = database(DataSet(state.range(0)));
  if (db == nullptr) {
    state.SkipWithError("real data set missing (MMVK_DATA)");
    return;
  }
  run_vulkan(state, *db, std::size_t(state.range(1)), 16, false);
}

BENCHMARK(BM_RealVulkan)
    ->ArgNames({"set", "batch"})
    ->ArgsProduct({{int(DataSet::Locomotion), int(DataSet::Volume), int(DataSet::VolumeMirrored)}, {1, 64, 1024, 8192}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK(BM_VulkanEndToEnd)
    ->ArgNames({"frames", "dims", "batch", "tile"})
    ->ArgsProduct({{22000, 417000}, {27}, {1, 64, 1024}, {16}})
    ->Args({417000, 27, 1024, 4})
    ->Args({417000, 27, 1024, 32})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VulkanKernel)
    ->ArgNames({"frames", "dims", "batch", "tile"})
    ->ArgsProduct({{22000, 417000}, {27}, {1, 64, 1024}, {16}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
#endif

void BM_RealFastBrute(benchmark::State& state) {
  const Database* db = database(DataSet(state.range(0)));
  if (db == nullptr) {
    state.SkipWithError("real data set missing (MMVK_DATA)");
    return;
  }
  ThreadPool pool(2);
  run_cpu_backend(state, BackendSpec{.name = "fast-brute", .pool = &pool}, *db, std::size_t(state.range(1)));
}

BENCHMARK(BM_RealFastBrute)
    ->ArgNames({"set", "batch"})
    ->ArgsProduct({{int(DataSet::Locomotion), int(DataSet::Volume), int(DataSet::VolumeMirrored)}, {1, 64, 1024}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

BENCHMARK(BM_FastBrute)
    ->ArgNames({"frames", "dims", "batch"})
    ->ArgsProduct({{22000, 417000}, {27}, {1, 64, 1024}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Reference)
    ->ArgNames({"frames", "dims", "batch"})
    ->ArgsProduct({{22000, 417000}, {27}, {1, 64}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mmvk::bench
