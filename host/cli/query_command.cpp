// mmvk query: batched search from a file of query vectors, one result line
// per query, so anyone can check the engine against their own brute force.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "backends/host_backends.hpp"
#include "mmvk/search/backends.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/search/explain.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/query/pose_query.hpp"
#include "mmvk/query/query_builder.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "user_cache_dir.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kQueryDescription =
    "Reads B queries as raw little-endian float32 [B x dims] (dims and their order as in `mmvk export`'s sidecar). "
    "Values are raw features, normalized here with the database's offsets and scales, or already normalized with "
    "--normalized. The queries may come from a pipe (--queries /dev/stdin); every other input must be a regular "
    "file.\n"
    "\n"
    "--pose-targets: one pose-matching query instead, from end-effector targets\n"
    "  {\"targets\": [{\"bone\": \"@left_foot\", \"position\": [x, y, z], \"velocity\": [x, y, z]}]}\n"
    "(character space, metres and m/s; see docs/search.md): only the targeted channels are weighted; prints each "
    "target's distance from the result.";

constexpr const char* kQueryOutput =
    "Output (--out, default stdout), tab-separated, '#' lines are comments:\n"
    "  <query index>\\t<frame>:<cost>\\t<frame>:<cost> ...   best first, k entries;\n"
    "  'none' where fewer than k frames are candidates. Costs are printed with\n"
    "  %.9g, which round-trips float32 exactly.\n"
    "--explain prints every query's explanation to stderr (--explain-queries: the\n"
    "named ones only): the winner's and the --frames' per-channel costs, the clip\n"
    "and its time, the bias and multiplier applied, and why frames are not\n"
    "candidates.\n"
    "\n"
    "The vulkan-* backends keep their pipeline cache between runs in\n"
    "$XDG_CACHE_HOME/mmvk (else ~/.cache/mmvk), one file per device.\n";

// The command line, parsed. Values checked against the database (frames,
// tags, channels) are kept as text until it is loaded.
struct QueryArgs {
  std::string database;
  std::optional<std::string> queries;
  std::optional<std::string> pose_targets;
  bool normalized = false;
  std::string backend = BackendSpec{}.name;
  std::optional<std::string> clusters;
  std::optional<std::uint32_t> nprobe;
  std::uint32_t k = 1;
  std::uint32_t threads = 0;
  std::optional<std::string> out;
  bool explain = false;
  std::optional<std::string> explain_queries;  // query indices; implies explain
  std::optional<std::string> frames;
  // Query options, applied to every query.
  std::optional<std::string> continuing;
  std::optional<float> continuing_bias;
  std::optional<float> continuing_multiplier;
  std::optional<std::uint32_t> exclusion_window;
  std::optional<std::string> require;
  std::optional<std::string> exclude;
  std::vector<std::pair<std::string, float>> weights;
};

// Everything a backend borrows, declared before it so that it outlives it.
// The Vulkan context is made when a Vulkan backend is (listing the backends
// for --help needs no device); its pipeline cache is kept between runs in
// the user's cache directory: loaded when the context is made, saved after
// the search; a missing directory, or a damaged or foreign file, is a note,
// never an error.
struct BackendHolder {
  std::unique_ptr<ThreadPool> pool;
  std::optional<ClusterTable> table;
  crowd::HostBackends backends{{.application_name = "mmvk", .device = std::nullopt, .device_option = "--device",
                                .cache_directory = user_cache_directory().value_or("")}};
  std::unique_ptr<SearchBackend> backend;
};

void print_note(const std::string& note) {
  if (!note.empty()) std::fprintf(stderr, "mmvk query: note: %s\n", note.c_str());
}

// The sections after the options: the backends (the registry's own list),
// the output format and the pipeline cache.
std::string query_footer() {
  return "backends (--backend NAME):\n" + crowd::HostBackends().registry().help() + "  (default " +
         BackendSpec{}.name + ")\n\n" + kQueryOutput;
}

void declare_search(CommandLine& cli, QueryArgs& out) {
  cli.text("--queries,--features", out.queries, "FILE", "the queries, float32 [B x dims]");
  cli.text("--pose-targets", out.pose_targets, "FILE", "one pose-matching query from end-effector targets (above)");
  cli.flag("--normalized", out.normalized, "the queries are already normalized");
  cli.text("--backend", out.backend, "NAME", "the search backend (below; default " + BackendSpec{}.name + ")");
  cli.text("--clusters", out.clusters, "FILE",
           "the cluster backends' tables (from `mmvk clusters`); without it they train the tables with the default "
           "k-means parameters");
  // A bad --nprobe fails the run (1), as its check against the backend does.
  cli.value_error_exit(1);
  cli.integer("--nprobe", out.nprobe, "N", "clusters searched per query by the *-nprobe backends (default " + std::to_string(BackendSpec{}.nprobe) + ")", 1);
  cli.value_error_exit(kUsageExit);
  cli.integer("--k", out.k, "K", "results per query, 1..16 (default 1)", 1, kMaxK);
  cli.integer("--threads", out.threads, "N", "0 = all cores (default), at most 1024", 0, ThreadPool::kMaxThreads);
  cli.text("--out", out.out, "FILE", "the results (default: stdout)");
  cli.flag("--explain", out.explain, "explain every query on stderr");
  cli.text("--explain-queries", out.explain_queries, "Q,Q,...", "explain only these queries (0-based; implies --explain)");
  cli.text("--frames,--frame", out.frames, "F,F,...", "frames whose costs --explain shows beside the winner's");
}

void declare_query_params(CommandLine& cli, QueryArgs& out) {
  cli.group("query options (applied to every query)");
  // Bad values here fail the run (1), as the checks against the database do.
  cli.value_error_exit(1);
  cli.text("--continuing", out.continuing, "F", "the frame each query continues from (a database frame)");
  cli.finite("--continuing-bias", out.continuing_bias, "X", "added to the continuing frame's cost");
  cli.finite("--continuing-multiplier", out.continuing_multiplier, "X", "multiplies the continuing frame's cost first");
  cli.integer("--exclusion-window", out.exclusion_window, "N",
              "frames within N of the continuing frame in its clip are no candidates");
  cli.text("--require", out.require, "TAG,TAG", "only frames with every one of these tags");
  cli.text("--exclude", out.exclude, "TAG,TAG", "no frame with any of these tags");
  cli.value("--weights", out.weights, "CHANNEL=W,...", "reweigh schema channels",
            [](const std::string& text) { return parse_weight_list("--weights", text); });
}

// Returns the exit code when the query must not run (help, usage errors).
std::optional<int> parse_query_args(Args args, QueryArgs& out) {
  CommandLine cli(kQueryCommand, kQueryDescription);
  cli.positional("db.mmdb", out.database);
  declare_search(cli, out);
  declare_query_params(cli, out);
  cli.footer(query_footer);
  if (const std::optional<int> exit_code = cli.parse(args)) return exit_code;
  if (!out.queries == !out.pose_targets) return cli.usage_error();  // exactly one of the two
  return std::nullopt;
}

Status make_backend(BackendHolder& holder, const Database& db, const QueryArgs& args, std::size_t batch) {
  const std::string& name = args.backend;
  BackendSpec spec;
  spec.name = name;
  spec.pool = holder.pool.get();
  if (args.nprobe) spec.nprobe = *args.nprobe;
  crowd::DeviceSearchLimits limits;
  limits.max_batch = static_cast<std::uint32_t>(std::max<std::size_t>(batch, 1));
  limits.max_k = args.k;
  // One search per run: warming up every kernel variant would compile (on
  // lavapipe, for seconds) kernels this run never uses.
  limits.warm_up = false;
  const BackendEntry* entry = holder.backends.registry().find(name);
  // An option the chosen backend would ignore is a mistake worth naming
  // (the user believes a table or a probe count is in effect).
  if (entry != nullptr && !entry->uses_cluster_table && args.clusters) {
    return make_error("--clusters: backend '" + name + "' uses no cluster table");
  }
  if (entry != nullptr && !entry->uses_nprobe && args.nprobe) {
    return make_error("--nprobe: backend '" + name + "' searches no subset of clusters (the *-nprobe backends do)");
  }
  if (entry != nullptr && entry->uses_cluster_table) {
    if (args.clusters) {
      MMVK_ASSIGN_OR_RETURN(holder.table, load_cluster_table(*args.clusters));
      spec.clusters = &*holder.table;
    } else {
      std::fputs("mmvk query: training k-means cluster tables (default parameters; train them once with\n"
                 "  `mmvk clusters` and pass --clusters to reuse them)\n",
                 stderr);
    }
  }
  MMVK_ASSIGN_OR_RETURN(holder.backend, holder.backends.make(spec, db, limits));
  print_note(holder.backends.driver_cache_note());
  print_note(holder.backends.pipeline_cache_note());
  return {};
}

Result<QueryParams> query_params(const Database& db, const QueryArgs& args) {
  QueryParams params;
  if (args.continuing) {
    // A frame of the database: 4294967295 (kNoFrame inside the library) is
    // no way to say "none"; leave the option out for that.
    MMVK_ASSIGN_OR_RETURN(params.continuing_frame, parse_u32("--continuing", *args.continuing, 0, db.frame_count() - 1));
  }
  if (args.continuing_bias) params.continuing_bias = *args.continuing_bias;
  if (args.continuing_multiplier) params.continuing_multiplier = *args.continuing_multiplier;
  if (args.exclusion_window) params.exclusion_window = *args.exclusion_window;
  for (const auto& [option, text, mask] : {std::tuple{"--require", &args.require, &params.require_all},
                                           std::tuple{"--exclude", &args.exclude, &params.exclude_any}}) {
    if (*text) {
      Result<TagMask> tags = db.tag_mask(split_list(**text));
      if (!tags) return make_error(std::string(option) + ": " + tags.message());
      *mask = *tags;
    }
  }
  for (const auto& [channel, weight] : args.weights) MMVK_TRY(set_channel_weight(db.schema(), params, channel, weight));
  return params;
}

std::string format_results(std::span<const Match> results, std::size_t count, std::uint32_t k) {
  std::string text;
  char cell[64];
  for (std::size_t q = 0; q < count; ++q) {
    text += std::to_string(q);
    for (std::uint32_t r = 0; r < k; ++r) {
      const Match& m = results[q * k + r];
      if (m.frame == kNoFrame) {
        text += "\tnone";
      } else {
        std::snprintf(cell, sizeof(cell), "\t%u:%.9g", m.frame, double(m.cost));
        text += cell;
      }
    }
    text += '\n';
  }
  return text;
}

// Before any work: --out must be writable and no input.
Status check_paths(const QueryArgs& args) {
  std::vector<NamedPath> paths = {{"the database", args.database, false}};
  if (args.queries) paths.push_back({"--queries", *args.queries, false});
  if (args.pose_targets) paths.push_back({"--pose-targets", *args.pose_targets, false});
  if (args.clusters) paths.push_back({"--clusters", *args.clusters, false});
  if (args.out) paths.push_back({"--out", *args.out, true});
  return check_command_paths(paths);
}

// A mistyped backend is reported before the database loads (seconds for a
// large one), in the words the registry would use.
Status check_backend_name(const std::string& name) {
  const crowd::HostBackends backends;
  const BackendRegistry& registry = backends.registry();
  if (registry.find(name) == nullptr) return make_error("unknown backend '" + name + "' (known: " + registry.names() + ")");
  return {};
}

// The queries to search, normalized: the file's rows, or the one pose query.
struct Queries {
  std::vector<float> features;  // [count x dims]
  std::size_t count = 0;
  std::vector<PoseTarget> pose_targets;
  std::optional<PoseQuery> pose;
};

Result<Queries> pose_query(const Database& db, const std::string& path) {
  Queries queries;
  MMVK_ASSIGN_OR_RETURN(queries.pose_targets, load_pose_targets(path));
  MMVK_ASSIGN_OR_RETURN(queries.pose, build_pose_query(db, queries.pose_targets, path));
  queries.features = queries.pose->features;
  queries.count = 1;
  return queries;
}

Result<Queries> file_queries(const Database& db, const std::string& path, bool normalized) {
  // One search takes at most kMaxBatch queries; a larger file is refused
  // before it is read (its rows, their copy and the results would each be
  // allocated at full size).
  std::error_code size_error;
  const std::uintmax_t query_bytes = std::filesystem::file_size(path, size_error);
  if (!size_error && query_bytes / (std::uintmax_t{4} * db.dims()) > kMaxBatch) {
    return make_error(path + ": " + std::to_string(query_bytes / (std::uintmax_t{4} * db.dims())) +
                      " queries, over the limit of " + std::to_string(kMaxBatch) + " per search; split the file");
  }
  Queries queries;
  MMVK_ASSIGN_OR_RETURN(queries.features,
                        read_f32_rows(path, db.dims(), std::nullopt,
                                      ReadOptions{std::uint64_t{kMaxBatch} * db.dims() * 4, /*allow_stream=*/true}));
  queries.count = queries.features.size() / db.dims();
  if (!normalized) {
    const std::vector<float> raw = queries.features;
    for (std::size_t q = 0; q < queries.count; ++q) {
      db.normalize(std::span<const float>(raw).subspan(q * db.dims(), db.dims()),
                   std::span<float>(queries.features).subspan(q * db.dims(), db.dims()));
    }
  }
  return queries;
}

// The query options, for every query; a pose query keeps the channels it
// does not target off (--weights may reweigh the targeted ones).
Result<std::vector<QueryParams>> all_query_params(const Database& db, const QueryArgs& args, const Queries& queries) {
  MMVK_ASSIGN_OR_RETURN(QueryParams params, query_params(db, args));
  if (queries.pose) {
    for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
      if (queries.pose->params.channel_weights[c] == 0.0f) params.channel_weights[c] = 0.0f;
    }
  }
  return std::vector<QueryParams>(queries.count, params);
}

// --explain's frames, checked before any work so that a typo does not fail
// after the results are printed.
Result<std::vector<std::uint32_t>> explain_frames(const Database& db, const QueryArgs& args) {
  std::vector<std::uint32_t> frames;
  if (!(args.explain || args.explain_queries) || !args.frames) return frames;
  for (const std::string& item : split_list(*args.frames)) {
    const Result<std::uint32_t> frame = parse_u32("--frames", item, 0, db.frame_count() - 1);
    if (!frame) {
      return make_error(frame.message() + " (the database has " + std::to_string(db.frame_count()) + " frames)");
    }
    frames.push_back(*frame);
  }
  return frames;
}

// The queries --explain explains: every query, or --explain-queries' list,
// checked against the batch before any work.
Result<std::vector<std::size_t>> explained_queries(const QueryArgs& args, std::size_t count) {
  std::vector<std::size_t> chosen;
  if (!args.explain_queries) {
    if (args.explain) for (std::size_t q = 0; q < count; ++q) chosen.push_back(q);
    return chosen;
  }
  const std::uint32_t last = std::uint32_t(std::min<std::size_t>(count - 1, UINT32_MAX));
  for (const std::string& item : split_list(*args.explain_queries)) {
    const Result<std::uint32_t> query = parse_u32("--explain-queries", item, 0, last);
    if (!query) return make_error(query.message() + " (the batch has " + std::to_string(count) + " queries)");
    chosen.push_back(*query);
  }
  return chosen;
}

// Each chosen query's explanation on stderr, in the order asked. A query's
// continuing frame is explained beside the winner (the frame it would keep
// playing), unless --frames names it already.
Status print_explanations(const Database& db, const Queries& queries, std::span<const QueryParams> params,
                          std::span<const std::size_t> chosen, std::span<const std::uint32_t> frames,
                          std::uint32_t k) {
  std::vector<std::uint32_t> shown;
  for (const std::size_t q : chosen) {
    const std::span<const float> query = std::span<const float>(queries.features).subspan(q * db.dims(), db.dims());
    const std::uint32_t continuing = params[q].continuing_frame;
    shown.assign(frames.begin(), frames.end());
    if (continuing != kNoFrame && std::find(shown.begin(), shown.end(), continuing) == shown.end()) {
      shown.push_back(continuing);
    }
    MMVK_ASSIGN_OR_RETURN(const Explanation explanation, explain_query(db, query, params[q], shown, k));
    std::fputs(("explain, query " + std::to_string(q) + ":\n" + format_explanation(db, explanation)).c_str(), stderr);
  }
  return {};
}

// Makes the backend, runs the one search and reports its speed on stderr.
Result<std::vector<Match>> search(BackendHolder& holder, const Database& db, const QueryArgs& args,
                                  const Queries& queries, std::span<const QueryParams> params) {
  MMVK_ASSIGN_OR_RETURN(holder.pool, ThreadPool::create(args.threads));
  MMVK_TRY(make_backend(holder, db, args, queries.count));
  std::vector<Match> results(queries.count * args.k);
  const auto start = std::chrono::steady_clock::now();
  MMVK_TRY(holder.backend->search(QueryBatch{queries.features, params, queries.count}, args.k, results));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (const Status saved = holder.backends.save_pipeline_cache(); !saved) {
    print_note("the pipeline cache was not saved: " + saved.message());
  }
  std::fprintf(stderr, "mmvk query: %zu queries, backend %s on %s, %.3f ms (%.0f queries/s), %.2f%% of rows evaluated\n",
               queries.count, std::string(holder.backend->name()).c_str(), holder.backend->device().c_str(), seconds * 1e3,
               double(queries.count) / seconds, 100.0 * holder.backend->stats().rows_fraction(db.frame_count()));
  return results;
}

Status write_results(const QueryArgs& args, std::string_view backend, std::span<const Match> results,
                     std::size_t count) {
  std::string text = "# mmvk query: " + args.database + ", backend " + std::string(backend) + ", k " +
                     std::to_string(args.k) + ", " + std::to_string(count) + " queries\n" +
                     "# query\tframe:cost ... (best first; none = no further candidate)\n";
  text += format_results(results, count, args.k);
  if (args.out) return write_file_atomically(*args.out, text);
  std::fputs(text.c_str(), stdout);
  return {};
}

// How far the best match lies from each pose target, on stderr.
void print_pose_errors(const Database& db, const Queries& queries, std::uint32_t frame) {
  const std::vector<PoseTargetError> errors = pose_target_errors(db, frame, queries.pose_targets);
  std::string text = "pose match: frame " + std::to_string(frame) + "\n";
  char line[200];
  for (std::size_t t = 0; t < errors.size(); ++t) {
    std::snprintf(line, sizeof(line), "  %-20s", queries.pose_targets[t].bone.c_str());
    text += line;
    if (errors[t].position_metres >= 0.0f) {
      std::snprintf(line, sizeof(line), " position off by %.4f m", double(errors[t].position_metres));
      text += line;
    }
    if (errors[t].velocity_metres_per_second >= 0.0f) {
      std::snprintf(line, sizeof(line), " velocity off by %.4f m/s", double(errors[t].velocity_metres_per_second));
      text += line;
    }
    text += "\n";
  }
  std::fputs(text.c_str(), stderr);
}

int run_query(Args args, const char*) {
  QueryArgs parsed;
  if (const std::optional<int> exit_code = parse_query_args(args, parsed)) return *exit_code;
  auto fail = [](const std::string& message) { return report_error("query", message, 1); };
  if (Status checked = check_paths(parsed); !checked) return fail(checked.message());
  if (Status known = check_backend_name(parsed.backend); !known) return fail(known.message());
  Result<Database> db = load_database(parsed.database);
  if (!db) return fail(db.message());
  Result<Queries> queries = parsed.pose_targets ? pose_query(*db, *parsed.pose_targets)
                                                : file_queries(*db, *parsed.queries, parsed.normalized);
  if (!queries) return fail(queries.message());
  Result<std::vector<QueryParams>> params = all_query_params(*db, parsed, *queries);
  if (!params) return fail(params.message());
  Result<std::vector<std::uint32_t>> frames = explain_frames(*db, parsed);
  if (!frames) return report_error("query", frames.message(), kUsageExit);
  Result<std::vector<std::size_t>> explained = explained_queries(parsed, queries->count);
  if (!explained) return report_error("query", explained.message(), kUsageExit);

  BackendHolder holder;
  Result<std::vector<Match>> results = search(holder, *db, parsed, *queries, *params);
  if (!results) return fail(results.message());
  if (Status written = write_results(parsed, holder.backend->name(), *results, queries->count); !written) {
    return fail(written.message());
  }
  if (queries->pose && (*results)[0].frame != kNoFrame) print_pose_errors(*db, *queries, (*results)[0].frame);
  if (Status printed = print_explanations(*db, *queries, *params, *explained, *frames, parsed.k); !printed) {
    return fail(printed.message());
  }
  return 0;
}

}  // namespace

const Command kQueryCommand{"query", "db.mmdb (--queries q.f32 | --pose-targets targets.json)",
                            "batched search, one result line per query", run_query};

}  // namespace mmvk::cli
