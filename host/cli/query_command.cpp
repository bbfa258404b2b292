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
#include <vector>

#include "cli_args.hpp"
#include "commands.hpp"
#include "mmvk/backends.hpp"
#include "mmvk/cluster_table.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/explain.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/pose_query.hpp"
#include "mmvk/query_builder.hpp"
#include "mmvk/thread_pool.hpp"

#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/lazy_context.hpp"
#include "user_cache_dir.hpp"
#endif

namespace mmvk::cli {

namespace {

constexpr const char* kQueryUsage =
    "usage: mmvk query db.mmdb --queries q.f32 [--normalized] [--backend NAME] [--k K]\n"
    "                  [--threads N] [--out results.tsv] [query options]\n"
    "                  [--explain [--frames F,F,...]]\n"
    "       mmvk query db.mmdb --pose-targets targets.json [the same options]\n"
    "\n"
    "Reads B queries as raw little-endian float32 [B x dims] (dims and their order\n"
    "as in `mmvk export`'s sidecar). Values are raw features, normalized here with\n"
    "the database's offsets and scales, or already normalized with --normalized.\n"
    "(--features is a synonym of --queries.) The queries may come from a pipe\n"
    "(--queries /dev/stdin); every other input must be a regular file.\n"
    "--pose-targets: one pose-matching query instead, from end-effector targets\n"
    "  {\"targets\": [{\"bone\": \"@left_foot\", \"position\": [x, y, z], \"velocity\": [x, y, z]}]}\n"
    "  (character space, metres and m/s; see docs/search.md): only the targeted\n"
    "  channels are weighted; prints each target's distance from the result.\n"
    "\n"
    "--backend NAME, one of:\n";

constexpr const char* kQueryUsageOptions =
    "  The cluster backends load --clusters table.mmkc (from `mmvk clusters`) when\n"
    "  given, else train the tables with the default k-means parameters. --nprobe N: clusters searched\n"
    "  per query by the *-nprobe backends (default 4).\n"
    "--k K: results per query, 1..16 (default 1). --threads N: 0 = all cores, at most 1024.\n"
    "\n"
    "query options (applied to every query):\n"
    "  --continuing F, --continuing-bias X, --continuing-multiplier X, --exclusion-window N,\n"
    "  --require TAG,TAG  --exclude TAG,TAG  --weights CHANNEL=W,CHANNEL=W\n"
    "\n"
    "Output (--out, default stdout), tab-separated, '#' lines are comments:\n"
    "  <query index>\\t<frame>:<cost>\\t<frame>:<cost> ...   best first, k entries;\n"
    "  'none' where fewer than k frames are candidates. Costs are printed with\n"
    "  %.9g, which round-trips float32 exactly.\n"
    "--explain prints the first query's explanation to stderr: the winner's and\n"
    "the --frames' per-channel costs, and why frames are not candidates.\n"
    "\n"
    "The vulkan-* backends keep their pipeline cache between runs in\n"
    "$XDG_CACHE_HOME/mmvk (else ~/.cache/mmvk), one file per device.\n";

// The Vulkan context, made when a Vulkan backend is (so that listing the
// backends for --help needs no device). Its pipeline cache is kept between
// runs in the user's cache directory: loaded when the context is made, saved
// after the search; a missing directory, or a damaged or foreign file, is a
// note, never an error.
#if defined(MMVK_HAS_VULKAN)
struct ContextHolder {
  vulkan::LazyContext lazy{{.context = {}, .cache_directory = user_cache_directory().value_or("")}};
};
#else
struct ContextHolder {};
#endif

// Everything a backend borrows, declared before it so that it outlives it.
struct BackendHolder {
  std::unique_ptr<ThreadPool> pool;
  std::optional<ClusterTable> table;
  ContextHolder context;  // created when a Vulkan backend is made
  std::unique_ptr<SearchBackend> backend;
};

#if defined(MMVK_HAS_VULKAN)
void report_pipeline_cache_note(const ContextHolder& context) {
  const std::string& note = context.lazy.pipeline_cache_note();
  if (!note.empty()) std::fprintf(stderr, "mmvk query: note: %s\n", note.c_str());
}

void save_pipeline_cache(const ContextHolder& context) {
  if (const Status saved = context.lazy.save_pipeline_cache(); !saved) {
    std::fprintf(stderr, "mmvk query: note: the pipeline cache was not saved: %s\n", saved.message().c_str());
  }
}
#endif

// The CPU backends, and the Vulkan ones when built with Vulkan, on
// `context`.
BackendRegistry query_backends([[maybe_unused]] ContextHolder& context) {
  BackendRegistry registry = cpu_backends();
#if defined(MMVK_HAS_VULKAN)
  const Status added = context.lazy.add_backends(registry);
  // The CPU and Vulkan names are distinct; a clash is a bug in mmvk itself.
  if (!added) std::fprintf(stderr, "mmvk query: %s\n", added.message().c_str());
#endif
  return registry;
}

std::string usage_text() {
  ContextHolder unused;
  std::string text = kQueryUsage;
  text += query_backends(unused).help();
  return text + "  (default " + BackendSpec{}.name + ")\n" + kQueryUsageOptions;
}

Status make_backend(BackendHolder& holder, const Database& db, const std::string& name, const ParsedArgs& args,
                    std::size_t batch, std::uint32_t k) {
  const BackendRegistry registry = query_backends(holder.context);
  BackendSpec spec;
  spec.name = name;
  spec.pool = holder.pool.get();
  spec.max_batch = static_cast<std::uint32_t>(std::max<std::size_t>(batch, 1));
  spec.max_k = k;
  // One search per run: warming up every kernel variant would compile (on
  // lavapipe, for seconds) kernels this run never uses.
  spec.warm_up = false;
  if (const auto text = args.value("--nprobe")) {
    MMVK_ASSIGN_OR_RETURN(spec.nprobe, parse_u32("--nprobe", *text, 1));
  }
  const BackendEntry* entry = registry.find(name);
  // An option the chosen backend would ignore is a mistake worth naming
  // (the user believes a table or a probe count is in effect).
  if (entry != nullptr && !entry->uses_cluster_table && args.value("--clusters")) {
    return make_error("--clusters: backend '" + name + "' uses no cluster table");
  }
  if (entry != nullptr && !entry->uses_nprobe && args.value("--nprobe")) {
    return make_error("--nprobe: backend '" + name + "' searches no subset of clusters (the *-nprobe backends do)");
  }
  if (entry != nullptr && entry->uses_cluster_table) {
    if (const auto path = args.value("--clusters")) {
      MMVK_ASSIGN_OR_RETURN(holder.table, load_cluster_table(*path));
      spec.clusters = &*holder.table;
    } else {
      std::fputs("mmvk query: training k-means cluster tables (default parameters; train them once with\n"
                 "  `mmvk clusters` and pass --clusters to reuse them)\n",
                 stderr);
    }
  }
  MMVK_ASSIGN_OR_RETURN(holder.backend, registry.make(spec, db));
#if defined(MMVK_HAS_VULKAN)
  report_pipeline_cache_note(holder.context);
#endif
  return {};
}

Result<QueryParams> query_params(const Database& db, const ParsedArgs& args) {
  QueryParams params;
  if (const auto text = args.value("--continuing")) {
    // A frame of the database: 4294967295 (kNoFrame inside the library) is
    // no way to say "none"; leave the option out for that.
    MMVK_ASSIGN_OR_RETURN(params.continuing_frame, parse_u32("--continuing", *text, 0, db.frame_count() - 1));
  }
  if (const auto text = args.value("--continuing-bias")) {
    MMVK_ASSIGN_OR_RETURN(params.continuing_bias, parse_float("--continuing-bias", *text));
  }
  if (const auto text = args.value("--continuing-multiplier")) {
    MMVK_ASSIGN_OR_RETURN(params.continuing_multiplier, parse_float("--continuing-multiplier", *text));
  }
  if (const auto text = args.value("--exclusion-window")) {
    MMVK_ASSIGN_OR_RETURN(params.exclusion_window, parse_u32("--exclusion-window", *text));
  }
  for (const auto& [option, mask] : {std::pair{"--require", &params.require_all}, std::pair{"--exclude", &params.exclude_any}}) {
    if (const auto text = args.value(option)) {
      Result<TagMask> tags = db.tag_mask(split_list(*text));
      if (!tags) return make_error(std::string(option) + ": " + tags.message());
      *mask = *tags;
    }
  }
  if (const auto text = args.value("--weights")) {
    MMVK_ASSIGN_OR_RETURN(const auto weights, parse_weight_list("--weights", *text));
    for (const auto& [channel, weight] : weights) MMVK_TRY(set_channel_weight(db.schema(), params, channel, weight));
  }
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

}  // namespace

int run_query(Args args) {
  const auto parsed = parse_args("query", args,
                                 {"--queries", "--features", "--backend", "--k", "--threads", "--out", "--frames",
                                  "--frame", "--clusters", "--nprobe", "--continuing", "--continuing-bias",
                                  "--continuing-multiplier", "--exclusion-window", "--require", "--exclude", "--weights", "--pose-targets"},
                                 {"--normalized", "--explain", "--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(usage_text().c_str(), stdout);
    return 0;
  }
  const auto queries_path = parsed->value("--queries") ? parsed->value("--queries") : parsed->value("--features");
  const auto pose_path = parsed->value("--pose-targets");
  if (parsed->positional.size() != 1 || !queries_path == !pose_path) {
    std::fputs(usage_text().c_str(), stderr);
    return 2;
  }
  auto fail = [](const std::string& message) { return report_error("query", message, 1); };
  std::uint32_t k = 1;
  if (const auto text = parsed->value("--k")) {
    const Result<std::uint32_t> value = parse_u32("--k", *text, 1, kMaxK);
    if (!value) return report_error("query", value.message(), 2);
    k = *value;
  }
  std::uint32_t threads = 0;
  if (const auto text = parsed->value("--threads")) {
    const Result<std::uint32_t> value = parse_u32("--threads", *text, 0, ThreadPool::kMaxThreads);
    if (!value) return report_error("query", value.message(), 2);
    threads = *value;
  }
  {
    // Before any work: --out must be writable and no input.
    std::vector<NamedPath> paths = {{"the database", parsed->positional[0], false}};
    if (queries_path) paths.push_back({parsed->value("--queries") ? "--queries" : "--features", *queries_path, false});
    if (pose_path) paths.push_back({"--pose-targets", *pose_path, false});
    if (const auto table = parsed->value("--clusters")) paths.push_back({"--clusters", *table, false});
    if (const auto out = parsed->value("--out")) paths.push_back({"--out", *out, true});
    if (Status checked = check_command_paths(paths); !checked) return fail(checked.message());
  }
  // A mistyped backend is reported before the database loads (seconds for
  // a large one), in the words the registry would use.
  const std::string backend_name = parsed->value("--backend").value_or(BackendSpec{}.name);
  {
    ContextHolder unused;
    const BackendRegistry registry = query_backends(unused);
    if (registry.find(backend_name) == nullptr) {
      return fail("unknown backend '" + backend_name + "' (known: " + registry.names() + ")");
    }
  }
  Result<Database> db = load_database(parsed->positional[0]);
  if (!db) return fail(db.message());
  std::vector<PoseTarget> pose_targets;
  std::optional<PoseQuery> pose;
  if (pose_path) {
    Result<std::vector<PoseTarget>> targets = load_pose_targets(*pose_path);
    if (!targets) return fail(targets.message());
    pose_targets = std::move(*targets);
    Result<PoseQuery> built = build_pose_query(*db, pose_targets, *pose_path);
    if (!built) return fail(built.message());
    pose = std::move(*built);
  } else {
    // One search takes at most kMaxBatch queries; a larger file is refused
    // before it is read (its rows, their copy and the results would each be
    // allocated at full size).
    std::error_code size_error;
    const std::uintmax_t query_bytes = std::filesystem::file_size(*queries_path, size_error);
    if (!size_error && query_bytes / (std::uintmax_t{4} * db->dims()) > kMaxBatch) {
      return fail(*queries_path + ": " + std::to_string(query_bytes / (std::uintmax_t{4} * db->dims())) +
                  " queries, over the limit of " + std::to_string(kMaxBatch) + " per search; split the file");
    }
  }
  Result<std::vector<float>> features =
      pose ? Result<std::vector<float>>(pose->features)
           : read_f32_rows(*queries_path, db->dims(), std::nullopt,
                           ReadOptions{std::uint64_t{kMaxBatch} * db->dims() * 4, /*allow_stream=*/true});
  if (!features) return fail(features.message());
  const std::size_t count = features->size() / db->dims();
  if (!pose && !parsed->has("--normalized")) {
    std::vector<float> raw = *features;
    for (std::size_t q = 0; q < count; ++q) {
      db->normalize(std::span<const float>(raw).subspan(q * db->dims(), db->dims()),
                    std::span<float>(*features).subspan(q * db->dims(), db->dims()));
    }
  }
  Result<QueryParams> params = query_params(*db, *parsed);
  if (!params) return fail(params.message());
  if (pose) {
    // --weights may reweigh the targeted channels; the others stay off.
    for (std::size_t c = 0; c < db->schema().channels.size(); ++c) {
      if (pose->params.channel_weights[c] == 0.0f) params->channel_weights[c] = 0.0f;
    }
  }
  const std::vector<QueryParams> all_params(count, *params);

  // --explain's frames are checked before any work, so that a typo does not
  // fail after the results are printed.
  std::vector<std::uint32_t> explain_frames;
  if (parsed->has("--explain")) {
    const auto list = parsed->value("--frames") ? parsed->value("--frames") : parsed->value("--frame");
    for (const std::string& item : list ? split_list(*list) : std::vector<std::string>{}) {
      const Result<std::uint32_t> frame = parse_u32("--frames", item, 0, db->frame_count() - 1);
      if (!frame) return report_error("query", frame.message() + " (the database has " +
                                                   std::to_string(db->frame_count()) + " frames)", 2);
      explain_frames.push_back(*frame);
    }
  }

  BackendHolder holder;
  Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(threads);
  if (!pool) return fail(pool.message());
  holder.pool = std::move(pool.value());
  const Status made = make_backend(holder, *db, backend_name, *parsed, count, k);
  if (!made) return fail(made.message());
  std::vector<Match> results(count * k);
  const auto start = std::chrono::steady_clock::now();
  const Status searched =
      holder.backend->search(QueryBatch{*features, all_params, count}, k, results);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!searched) return fail(searched.message());
#if defined(MMVK_HAS_VULKAN)
  save_pipeline_cache(holder.context);
#endif
  std::fprintf(stderr, "mmvk query: %zu queries, backend %s, %.3f ms (%.0f queries/s), %.2f%% of rows evaluated\n",
               count, std::string(holder.backend->name()).c_str(), seconds * 1e3, double(count) / seconds,
               100.0 * holder.backend->stats().rows_fraction(db->frame_count()));

  std::string text = "# mmvk query: " + parsed->positional[0] + ", backend " + std::string(holder.backend->name()) +
                     ", k " + std::to_string(k) + ", " + std::to_string(count) + " queries\n" +
                     "# query\tframe:cost ... (best first; none = no further candidate)\n";
  text += format_results(results, count, k);
  if (const auto out = parsed->value("--out")) {
    if (Status written = write_file_atomically(*out, text); !written) return fail(written.message());
  } else {
    std::fputs(text.c_str(), stdout);
  }

  if (pose && results[0].frame != kNoFrame) {
    const std::vector<PoseTargetError> errors = pose_target_errors(*db, results[0].frame, pose_targets);
    std::string text = "pose match: frame " + std::to_string(results[0].frame) + "\n";
    char line[200];
    for (std::size_t t = 0; t < errors.size(); ++t) {
      std::snprintf(line, sizeof(line), "  %-20s", pose_targets[t].bone.c_str());
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
  if (parsed->has("--explain")) {
    Result<Explanation> explanation = explain_query(*db, std::span<const float>(*features).first(db->dims()),
                                                    all_params[0], explain_frames, k);
    if (!explanation) return fail(explanation.message());
    std::fputs(("explain, query 0:\n" + format_explanation(*db, *explanation)).c_str(), stderr);
  }
  return 0;
}

}  // namespace mmvk::cli
