// mmvk_first_search: how long the first Vulkan search of a fresh process
// takes next to a steady-state search, with and without the pipeline cache
// (mmvk/vulkan/pipeline_cache_file.hpp) and Mesa's shader cache. Run it as
// separate processes; clear or point the caches to measure cold and warm:
//
//   MESA_SHADER_CACHE_DIR=$(mktemp -d) build/bench/mmvk_first_search db.mmdb --cache-dir $(mktemp -d)   # cold
//   (same directories again)                                                                            # warm
//
// Prints one line of key=value pairs (milliseconds): wall time, and the
// process's CPU time (every thread, lavapipe's included), which a loaded
// machine distorts less. The queries are B rows of the database spread
// over it; no query options.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/pipeline_cache_file.hpp"
#include "mmvk/vulkan/vulkan_brute_force.hpp"
#include "mmvk/vulkan/vulkan_cluster_search.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); }

// CPU time of the whole process, milliseconds.
double process_cpu_ms() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return double(now.tv_sec) * 1e3 + double(now.tv_nsec) * 1e-6;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

constexpr const char* kUsage =
    "usage: mmvk_first_search db.mmdb [--mode brute|clusters] [--clusters table.mmkc] [--batch B] [--k K]\n"
    "                         [--cache-dir DIR] [--warm-up] [--repeat N]\n"
    "--cache-dir: load the pipeline cache file from DIR first and save it at the end.\n"
    "--warm-up: call VulkanSearch::warm_up() before the first search (timed apart).\n";

int fail(const std::string& message) {
  std::fprintf(stderr, "mmvk_first_search: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  std::string db_path = argv[1];
  std::string mode = "brute";
  std::string clusters_path;
  std::string cache_dir;
  std::uint32_t batch = 1024;
  std::uint32_t k = 1;
  std::uint32_t repeat = 10;
  bool warm_up = false;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--mode" && has_value) {
      mode = argv[++i];
    } else if (arg == "--clusters" && has_value) {
      clusters_path = argv[++i];
    } else if (arg == "--cache-dir" && has_value) {
      cache_dir = argv[++i];
    } else if (arg == "--batch" && has_value) {
      batch = static_cast<std::uint32_t>(std::strtoul(argv[++i], nullptr, 10));
    } else if (arg == "--k" && has_value) {
      k = static_cast<std::uint32_t>(std::strtoul(argv[++i], nullptr, 10));
    } else if (arg == "--repeat" && has_value) {
      repeat = std::max(1u, static_cast<std::uint32_t>(std::strtoul(argv[++i], nullptr, 10)));
    } else if (arg == "--warm-up") {
      warm_up = true;
    } else {
      std::fputs(kUsage, stderr);
      return 2;
    }
  }
  mmvk::Result<mmvk::Database> db = mmvk::load_database(db_path);
  if (!db) return fail(db.message());
  mmvk::ClusterTable table;
  mmvk::vulkan::VulkanSearchOptions options;
  options.max_batch = std::max(batch, 1u);
  options.max_k = k;
  options.warm_up = false;  // timed apart below
  if (mode == "clusters") {
    mmvk::Result<mmvk::ClusterTable> loaded =
        clusters_path.empty() ? mmvk::train_cluster_table(*db, mmvk::KMeansParams{}) : mmvk::load_cluster_table(clusters_path);
    if (!loaded) return fail(loaded.message());
    table = std::move(*loaded);
  } else if (mode != "brute") {
    return fail("--mode is brute or clusters");
  }

  std::vector<float> queries;
  for (std::uint32_t q = 0; q < batch; ++q) {
    const auto row = db->row(static_cast<std::uint32_t>(std::uint64_t{q} * db->frame_count() / batch));
    queries.insert(queries.end(), row.begin(), row.end());
  }
  const mmvk::QueryBatch query_batch{queries, {}, batch};
  std::vector<mmvk::Match> out(std::size_t{batch} * k);

  Clock::time_point start = Clock::now();
  mmvk::Result<std::unique_ptr<mmvk::vulkan::Context>> context = mmvk::vulkan::Context::create();
  if (!context) return fail(context.message());
  const double context_ms = ms_since(start);
  std::string note;
  start = Clock::now();
  if (!cache_dir.empty()) note = mmvk::vulkan::load_pipeline_cache_file(**context, cache_dir);
  const double load_ms = ms_since(start);

  start = Clock::now();
  std::unique_ptr<mmvk::vulkan::VulkanSearch> search;
  if (mode == "clusters") {
    auto created = mmvk::vulkan::VulkanClusterSearch::create(**context, *db, table, options);
    if (!created) return fail(created.message());
    search = std::move(created).value();
  } else {
    auto created = mmvk::vulkan::VulkanBruteForce::create(**context, *db, options);
    if (!created) return fail(created.message());
    search = std::move(created).value();
  }
  const double create_ms = ms_since(start);
  double warm_up_ms = 0.0;
  if (warm_up) {
    start = Clock::now();
    if (mmvk::Status warmed = search->warm_up(); !warmed) return fail(warmed.message());
    warm_up_ms = ms_since(start);
  }
  std::vector<double> times;
  std::vector<double> cpu_times;
  for (std::uint32_t r = 0; r <= repeat; ++r) {
    start = Clock::now();
    const double cpu_start = process_cpu_ms();
    if (mmvk::Status searched = search->search(query_batch, k, out); !searched) return fail(searched.message());
    cpu_times.push_back(process_cpu_ms() - cpu_start);
    times.push_back(ms_since(start));
  }
  const double first_ms = times.front();
  const double median_ms = median(std::vector<double>(times.begin() + 1, times.end()));
  const double first_cpu_ms = cpu_times.front();
  const double median_cpu_ms = median(std::vector<double>(cpu_times.begin() + 1, cpu_times.end()));
  double save_ms = 0.0;
  if (!cache_dir.empty()) {
    start = Clock::now();
    if (mmvk::Status saved = mmvk::vulkan::save_pipeline_cache_file(**context, cache_dir); !saved) {
      return fail(saved.message());
    }
    save_ms = ms_since(start);
  }
  std::printf(
      "mode=%s frames=%u batch=%u k=%u warm_up=%d context_ms=%.1f cache_load_ms=%.2f create_ms=%.1f warm_up_ms=%.1f "
      "first_search_ms=%.2f steady_median_ms=%.2f first_over_steady=%.2f first_cpu_ms=%.2f steady_cpu_ms=%.2f "
      "cpu_first_over_steady=%.2f cache_save_ms=%.2f%s%s\n",
      mode.c_str(), db->frame_count(), batch, k, warm_up ? 1 : 0, context_ms, load_ms, create_ms, warm_up_ms, first_ms,
      median_ms, first_ms / median_ms, first_cpu_ms, median_cpu_ms, first_cpu_ms / median_cpu_ms, save_ms,
      note.empty() ? "" : " note=", note.c_str());
  return 0;
}
