// Cluster-table benchmarks: queries/s of the cluster-pruned backend (exact
// and clusters-nprobe 1/4/16) beside the fast exact brute force and box-pruned
// backends, with the fraction of rows evaluated and recall@1 against the
// exact answers, for B in {1, 64, 1024}, and k-means training time.
//
// Data: a synthetic motion-like database (clips of smooth walks on a 6-d
// latent manifold embedded in the default schema's 27-d channel layout), MMVK_BENCH_CLUSTER_FRAMES frames
// (default 417000, the Bandai volume set's size), and the Bandai locomotion
// set (~22k frames, default schema). register_cluster_benchmarks() takes any
// Database provider, so the volume sets plug in the same way.
//
// Query streams (1024 queries each, fixed seeds):
//   continue   - a frame's own features plus small noise;
//   transition - the first 15 dims (the default schema's pose: feet
//                positions and velocities, hip velocity) of one frame with
//                the trajectory of another (a character changing direction);
//   random     - uniform within the data's per-dimension range.
// Recall@1 compares the frame found with the exact one (FastSearch brute
// force, which is bit-identical to the reference and much faster to run).
#include <benchmark/benchmark.h>

#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mmvk/search/backends.hpp"
#include "mmvk/search/cluster_search.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"

namespace mmvk::bench {
namespace {

constexpr std::size_t kStreamQueries = 1024;
const char* const kStreams[] = {"continue", "transition", "random"};
constexpr std::uint32_t kBatchSizes[] = {1, 64, 1024};

// The rows: registry backends (mmvk/search/backends.hpp) by name with the nprobe.
struct Variant {
  const char* label;
  const char* backend;
  std::uint32_t nprobe = 0;
};
constexpr Variant kVariants[] = {
    {"fast-brute", "fast-brute"},
    {"fast-box", "fast-box"},
    {"clusters", "clusters"},
    {"clusters-nprobe1", "clusters-nprobe", 1},
    {"clusters-nprobe4", "clusters-nprobe", 4},
    {"clusters-nprobe16", "clusters-nprobe", 16},
};

double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
double gauss(std::mt19937_64& rng) {
  return std::sqrt(-2.0 * std::log(1.0 - unit(rng))) * std::cos(6.283185307179586 * unit(rng));
}

Database synthetic_database(std::uint32_t frames) {
  std::mt19937_64 rng(2024);
  DatabaseParts parts;
  for (std::uint32_t dims : {3u, 3u, 3u, 3u, 3u, 6u, 6u}) {
    FeatureChannel channel;
    channel.name = std::string("c").append(std::to_string(parts.schema.channels.size()));
    channel.kind = ChannelKind::Custom;
    channel.custom_dims = dims;
    parts.schema.channels.push_back(channel);
  }
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  parts.normalization.assign(dims, DimNormalization{});
  parts.frame_flags.assign(frames, 0);
  parts.features.resize(std::size_t{frames} * dims);
  // Motion features are strongly correlated (feet, hips and trajectory move
  // together), so the rows lie near a low-dimensional manifold: a smooth
  // 6-d latent walk per clip, mapped through a fixed random linear map and a
  // tanh into 27 dims, plus a little independent noise.
  constexpr std::uint32_t kLatent = 6;
  std::vector<double> map(std::size_t{dims} * kLatent);
  for (double& m : map) m = gauss(rng) / std::sqrt(double(kLatent));
  const std::uint32_t clip_frames = 300;
  std::vector<double> latent(kLatent);
  std::vector<double> velocity(kLatent);
  for (std::uint32_t first = 0; first < frames; first += clip_frames) {
    Clip clip;
    clip.name = std::string("clip").append(std::to_string(parts.clips.size()));
    clip.first_frame = first;
    clip.frame_count = std::min(clip_frames, frames - first);
    for (double& v : latent) v = gauss(rng);
    for (double& v : velocity) v = 0.0;
    for (std::uint32_t f = first; f < first + clip.frame_count; ++f) {
      for (std::uint32_t j = 0; j < kLatent; ++j) {
        velocity[j] = 0.9 * velocity[j] + 0.02 * gauss(rng);
        latent[j] = 0.995 * latent[j] + velocity[j];
      }
      for (std::uint32_t d = 0; d < dims; ++d) {
        double v = 0.0;
        for (std::uint32_t j = 0; j < kLatent; ++j) v += map[std::size_t{d} * kLatent + j] * latent[j];
        parts.features[std::size_t{f} * dims + d] = static_cast<float>(1.5 * std::tanh(v) + 0.02 * gauss(rng));
      }
    }
    parts.clips.push_back(clip);
  }
  Result<Database> db = Database::create(std::move(parts));
  if (!db.ok()) {
    std::fprintf(stderr, "cluster_bench: %s\n", db.message().c_str());
    std::abort();
  }
  return std::move(db).value();
}

// Everything one database's benchmarks share, built on first use.
struct Setup {
  const Database* db = nullptr;
  // MMVK_BENCH_THREADS sets the pool size (default: every core).
  ThreadPool pool{static_cast<unsigned>(std::getenv("MMVK_BENCH_THREADS") ? std::atoi(std::getenv("MMVK_BENCH_THREADS")) : 0)};
  ClusterTable table;
  double training_seconds = 0.0;
  std::map<std::string, std::unique_ptr<SearchBackend>> backends;
  std::map<std::string, std::vector<float>> queries;       // [1024 x dims] per stream
  std::map<std::string, std::vector<std::uint32_t>> truth;  // exact frame per query
};

std::vector<float> make_stream(const Database& db, const std::string& stream) {
  std::mt19937_64 rng(stream == "continue" ? 1 : stream == "transition" ? 2 : 3);
  const std::uint32_t dims = db.dims();
  // Pose channels come first (the default schema's order: feet, hips), the
  // trajectory last; here the first 15 dims play the pose.
  const std::uint32_t pose_dims = std::min<std::uint32_t>(15, dims);
  std::vector<float> lo(dims, INFINITY), hi(dims, -INFINITY);
  for (std::uint32_t f = 0; f < db.frame_count(); f += 17) {
    for (std::uint32_t d = 0; d < dims; ++d) {
      lo[d] = std::min(lo[d], db.row(f)[d]);
      hi[d] = std::max(hi[d], db.row(f)[d]);
    }
  }
  std::vector<float> q(kStreamQueries * dims);
  for (std::size_t i = 0; i < kStreamQueries; ++i) {
    const auto a = db.row(static_cast<std::uint32_t>(rng() % db.frame_count()));
    const auto b = db.row(static_cast<std::uint32_t>(rng() % db.frame_count()));
    for (std::uint32_t d = 0; d < dims; ++d) {
      float v;
      if (stream == "continue") v = a[d] + static_cast<float>(0.05 * gauss(rng));
      else if (stream == "transition") v = d < pose_dims ? a[d] : b[d];
      else v = lo[d] + static_cast<float>(unit(rng)) * (hi[d] - lo[d]);
      q[i * dims + d] = v;
    }
  }
  return q;
}

Setup& setup_for(const std::string& label, const std::function<const Database*()>& provider) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  std::unique_ptr<Setup>& slot = cache[label];
  if (slot) return *slot;
  slot = std::make_unique<Setup>();
  Setup& s = *slot;
  s.db = provider();
  if (s.db == nullptr) return s;
  const auto start = std::chrono::steady_clock::now();
  Result<ClusterTable> table = train_cluster_table(*s.db, KMeansParams{}, s.pool);
  s.training_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!table.ok()) {
    std::fprintf(stderr, "cluster_bench: %s\n", table.message().c_str());
    s.db = nullptr;
    return s;
  }
  s.table = std::move(table).value();
  const BackendRegistry registry = cpu_backends();
  for (const Variant& variant : kVariants) {
    BackendSpec spec{.name = variant.backend, .pool = &s.pool, .clusters = &s.table};
    spec.nprobe = variant.nprobe;
    auto backend = registry.make(spec, *s.db);
    if (!backend.ok()) {
      std::fprintf(stderr, "cluster_bench: %s\n", backend.message().c_str());
      std::abort();
    }
    s.backends[variant.label] = std::move(backend).value();
  }
  for (const char* stream : kStreams) {
    s.queries[stream] = make_stream(*s.db, stream);
    std::vector<Match> out(kStreamQueries);
    const Status status = s.backends["fast-brute"]->search({s.queries[stream], {}, kStreamQueries}, 1, out);
    if (!status.ok()) std::abort();
    for (const Match& m : out) s.truth[stream].push_back(m.frame);
  }
  s.backends["fast-brute"]->reset_stats();
  return s;
}

void run_search(benchmark::State& state, const std::string& label, const std::function<const Database*()>& provider,
                const std::string& backend_name, const std::string& stream, std::uint32_t batch) {
  Setup& s = setup_for(label, provider);
  if (s.db == nullptr) {
    state.SkipWithError("database unavailable");
    return;
  }
  SearchBackend& backend = *s.backends.at(backend_name);
  const std::vector<float>& all = s.queries.at(stream);
  const std::vector<std::uint32_t>& truth = s.truth.at(stream);
  std::vector<Match> out(batch);
  backend.reset_stats();
  std::size_t offset = 0;
  std::uint64_t hits = 0;
  std::uint64_t total = 0;
  timespec cpu_start{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_start);
  for (auto _ : state) {
    const QueryBatch q{std::span<const float>(all).subspan(offset * s.db->dims(), std::size_t{batch} * s.db->dims()), {},
                       batch};
    if (!backend.search(q, 1, out).ok()) {
      state.SkipWithError("search failed");
      return;
    }
    for (std::uint32_t i = 0; i < batch; ++i) hits += out[i].frame == truth[offset + i];
    total += batch;
    offset = (offset + batch) % kStreamQueries;
  }
  timespec cpu_end{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &cpu_end);
  const double cpu_seconds = double(cpu_end.tv_sec - cpu_start.tv_sec) + 1e-9 * double(cpu_end.tv_nsec - cpu_start.tv_nsec);
  state.counters["queries/s"] = benchmark::Counter(double(total), benchmark::Counter::kIsRate);
  // Process CPU time per query (all threads): steadier than wall time on a
  // machine shared with other work.
  state.counters["cpu_us/q"] = total == 0 ? 0.0 : 1e6 * cpu_seconds / double(total);
  state.counters["rows"] = backend.stats().rows_fraction(s.db->frame_count());
  state.counters["recall@1"] = total == 0 ? 0.0 : double(hits) / double(total);
  if (auto* clusters = dynamic_cast<ClusterSearch*>(&backend); clusters != nullptr && total > 0) {
    state.counters["clusters/q"] = double(clusters->counters().clusters_visited) / double(total);
    state.counters["tiles/q"] = double(clusters->counters().tiles_checked) / double(total);
  }
}

}  // namespace

// Registers the search and training benchmarks for one database.
void register_cluster_benchmarks(const std::string& label, std::function<const Database*()> provider) {
  benchmark::RegisterBenchmark(("clusters/" + label + "/train").c_str(), [label, provider](benchmark::State& state) {
    Setup& s = setup_for(label, provider);
    for (auto _ : state) benchmark::DoNotOptimize(s.table.cluster_count);
    state.counters["train_s"] = s.training_seconds;
    state.counters["clusters"] = s.table.cluster_count;
    state.counters["frames"] = s.db ? s.db->frame_count() : 0;
  })->Iterations(1);
  for (const char* stream : kStreams) {
    for (const Variant& variant : kVariants) {
      const std::string backend = variant.label;
      for (std::uint32_t batch : kBatchSizes) {
        const std::string name = "clusters/" + label + "/" + stream + "/" + backend + "/B:" + std::to_string(batch);
        benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& state) {
          run_search(state, label, provider, backend, stream, batch);
        })->UseRealTime()->MinTime(0.3);
      }
    }
  }
}

namespace {

// The Bandai locomotion set (bandai-namco-nc/locomotion-normal under
// MMVK_DATA or ../shared/data), built with the default schema on first use.
const Database* locomotion_database() {
  static std::unique_ptr<Database> db;
  static bool tried = false;
  if (tried) return db.get();
  tried = true;
  const char* env = std::getenv("MMVK_DATA");
  const std::filesystem::path data = env && *env ? std::filesystem::path(env) : std::filesystem::path(MMVK_DEFAULT_DATA_DIR);
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc" / "locomotion-normal");
  if (!manifest.ok()) {
    std::fprintf(stderr, "cluster_bench: %s\n", manifest.message().c_str());
    return nullptr;
  }
  ThreadPool pool;
  BuildOptions options;
  options.pool = &pool;
  Result<Database> built = build_database(*manifest, options);
  if (!built.ok()) {
    std::fprintf(stderr, "cluster_bench: %s\n", built.message().c_str());
    return nullptr;
  }
  db = std::make_unique<Database>(std::move(built).value());
  return db.get();
}

const bool registered = [] {
  register_cluster_benchmarks("locomotion", locomotion_database);
  const char* env = std::getenv("MMVK_BENCH_CLUSTER_FRAMES");
  const std::uint32_t frames = env && *env ? static_cast<std::uint32_t>(std::strtoul(env, nullptr, 10)) : 417000;
  register_cluster_benchmarks("synthetic" + std::to_string(frames / 1000) + "k", [frames]() -> const Database* {
    static const Database db = synthetic_database(frames);
    return &db;
  });
  return true;
}();

}  // namespace

}  // namespace mmvk::bench
