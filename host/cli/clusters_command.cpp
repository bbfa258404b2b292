// mmvk clusters: trains the k-means cluster tables of the cluster backends
// once and saves them (.mmkc), so `mmvk query --clusters` and the crowd host
// reuse them instead of training (seconds at 400k frames) on every run.
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kClustersDescription =
    "Trains the k-means cluster tables that the cluster backends (clusters, clusters-nprobe, vulkan-clusters, "
    "vulkan-nprobe) search, and saves them for `mmvk query --clusters table.mmkc`. A table belongs to the database "
    "it was trained on (its content hash): using it with another database is an error. Training is deterministic: "
    "the same options give the same table everywhere.";

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

int run_clusters(Args args, const char*) {
  std::string database;
  std::string output;
  KMeansParams params;
  unsigned threads = 0;
  bool always_progress = false;
  bool no_progress = false;
  CommandLine cli(kClustersCommand, kClustersDescription);
  cli.positional("db.mmdb", database);
  cli.text("-o,--output", output, "FILE", "the table file to write (required)")->required();
  cli.integer("--clusters", params.clusters, "K", "number of clusters (default: round(sqrt(frames)))", 1);
  // The defaults in the help are the parameters' own.
  cli.integer("--iterations", params.iterations, "N",
              "Lloyd iterations, stops early when stable (default " + std::to_string(params.iterations) + ")");
  cli.integer("--seed", params.seed, "S", "k-means++ seed (default " + std::to_string(params.seed) + ")", 0,
              std::numeric_limits<std::uint64_t>::max());
  cli.integer("--training-frames", params.max_training_frames, "M",
              "train on at most M frames drawn from the seed, 0 = all (default " +
                  std::to_string(params.max_training_frames) + "); every frame is then assigned");
  cli.integer("--threads", threads, "N", "training threads, 0 = all cores (default)", 0, ThreadPool::kMaxThreads);
  cli.flag("--progress", always_progress, "show the progress bar even when stderr is not a terminal");
  cli.flag("--no-progress", no_progress, "never show it");
  if (const std::optional<int> exit_code = cli.parse(args)) return *exit_code;

  const NamedPath paths[] = {{"the database", database, false}, {"-o", output, true}};
  if (Status checked = check_command_paths(paths); !checked) return report_error("clusters", checked.message(), 1);
  Result<Database> db = load_database(database);
  if (!db) return report_error("clusters", db.message(), 1);
  Result<std::unique_ptr<ThreadPool>> pool_made = ThreadPool::create(threads);
  if (!pool_made) return report_error("clusters", pool_made.message(), 1);
  ThreadPool& pool = **pool_made;
  const bool show_progress = !no_progress && (always_progress || stderr_is_terminal());
  const TrainingProgressFn progress = show_progress ? TrainingProgressFn(draw_progress) : TrainingProgressFn();
  const auto start = std::chrono::steady_clock::now();
  Result<ClusterTable> table = train_cluster_table(*db, params, pool, progress);
  if (!table) return report_error("clusters", table.message(), 1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (Status saved = save_cluster_table(*table, output); !saved) return report_error("clusters", saved.message(), 1);
  std::printf("wrote %s: %s clusters over %s frames (trained in %.2f s)\n", output.c_str(),
              thousands(table->cluster_count).c_str(), thousands(db->frame_count()).c_str(), seconds);
  return 0;
}

}  // namespace

const Command kClustersCommand{"clusters", "db.mmdb -o table.mmkc",
                               "train and save the cluster tables (query --clusters)", run_clusters};

}  // namespace mmvk::cli
