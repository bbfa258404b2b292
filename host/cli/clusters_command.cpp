// mmvk clusters: trains the k-means cluster tables of the cluster backends
// once and saves them (.mmkc), so `mmvk query --clusters` and the crowd host
// reuse them instead of training (seconds at 400k frames) on every run.
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "mmvk/cluster_table.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kClustersUsage =
    "usage: mmvk clusters db.mmdb -o table.mmkc [options]\n"
    "\n"
    "Trains the k-means cluster tables that the cluster backends (clusters,\n"
    "clusters-nprobe, vulkan-clusters, vulkan-nprobe) search, and saves them for\n"
    "`mmvk query --clusters table.mmkc`. A table belongs to the database it was\n"
    "trained on (its content hash): using it with another database is an error.\n"
    "Training is deterministic: the same options give the same table everywhere.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE        the table file to write (required)\n"
    "  --clusters K             number of clusters (default: round(sqrt(frames)))\n"
    "  --iterations N           Lloyd iterations, stops early when stable (default 25)\n"
    "  --seed S                 k-means++ seed (default 1234)\n"
    "  --training-frames M      train on at most M frames drawn from the seed, 0 = all\n"
    "                           (default 65536); every frame is then assigned\n"
    "  --threads N              training threads, 0 = all cores (default)\n"
    "  --progress               show the progress bar even when stderr is not a terminal\n"
    "  --no-progress            never show it\n";

// Redraws one line on stderr, at most every 100 ms (and always at the end).
void draw_progress(const TrainingProgress& progress) {
  static std::chrono::steady_clock::time_point last_draw;  // the CLI's own state, one training per process
  const auto now = std::chrono::steady_clock::now();
  const bool done = progress.fraction >= 1.0;
  if (!done && now - last_draw < std::chrono::milliseconds(100)) return;
  last_draw = now;
  std::fprintf(stderr, "\r%s %3d%%  %-9s %u/%u   ", progress_bar(progress.fraction).c_str(),
               int(progress.fraction * 100.0), progress.stage, progress.step, progress.steps);
  if (done) std::fputc('\n', stderr);
  std::fflush(stderr);
}

}  // namespace

int run_clusters(Args args) {
  const auto parsed = parse_args("clusters", args,
                                 {"-o", "--output", "--clusters", "--iterations", "--seed", "--training-frames",
                                  "--threads"},
                                 {"--progress", "--no-progress", "--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(kClustersUsage, stdout);
    return 0;
  }
  std::optional<std::string> output = parsed->value("-o");
  if (!output) output = parsed->value("--output");
  if (parsed->positional.size() != 1 || !output) {
    std::fputs(kClustersUsage, stderr);
    return 2;
  }
  KMeansParams params;
  unsigned threads = 0;
  constexpr std::uint32_t kAny = std::numeric_limits<std::uint32_t>::max();
  const struct {
    const char* option;
    std::uint32_t* value;
    std::uint32_t min;
    std::uint32_t max;
  } counts[] = {{"--clusters", &params.clusters, 1, kAny},
                {"--iterations", &params.iterations, 0, kAny},
                {"--training-frames", &params.max_training_frames, 0, kAny},
                {"--threads", &threads, 0, ThreadPool::kMaxThreads}};
  for (const auto& count : counts) {
    if (const auto text = parsed->value(count.option)) {
      Result<std::uint32_t> value = parse_u32(count.option, *text, count.min, count.max);
      if (!value) return report_error("clusters", value.message(), 2);
      *count.value = *value;
    }
  }
  if (const auto text = parsed->value("--seed")) {
    Result<std::uint64_t> seed = parse_integer("--seed", *text);
    if (!seed) return report_error("clusters", seed.message(), 2);
    params.seed = *seed;
  }

  const NamedPath paths[] = {{"the database", parsed->positional[0], false}, {"-o", *output, true}};
  if (Status checked = check_command_paths(paths); !checked) return report_error("clusters", checked.message(), 1);
  Result<Database> db = load_database(parsed->positional[0]);
  if (!db) return report_error("clusters", db.message(), 1);
  Result<std::unique_ptr<ThreadPool>> pool_made = ThreadPool::create(threads);
  if (!pool_made) return report_error("clusters", pool_made.message(), 1);
  ThreadPool& pool = **pool_made;
  const bool show_progress = !parsed->has("--no-progress") && (parsed->has("--progress") || stderr_is_terminal());
  const TrainingProgressFn progress = show_progress ? TrainingProgressFn(draw_progress) : TrainingProgressFn();
  const auto start = std::chrono::steady_clock::now();
  Result<ClusterTable> table = train_cluster_table(*db, params, pool, progress);
  if (!table) return report_error("clusters", table.message(), 1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (Status saved = save_cluster_table(*table, *output); !saved) return report_error("clusters", saved.message(), 1);
  std::printf("wrote %s: %s clusters over %s frames (trained in %.2f s)\n", output->c_str(),
              thousands(table->cluster_count).c_str(), thousands(db->frame_count()).c_str(), seconds);
  return 0;
}

}  // namespace mmvk::cli
