// mmvk build: manifest (or folder of BVH) -> .mmdb database file.
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/manifest.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kBuildUsage =
    "usage: mmvk build <manifest.json | bvh-dir> -o db.mmdb [options]\n"
    "\n"
    "Builds a motion matching database from BVH motion capture. A folder of BVH\n"
    "is built with the default schema and options; a JSON manifest names clips,\n"
    "tags, flags and options (see runtime/include/mmvk/manifest.hpp).\n"
    "\n"
    "options:\n"
    "  -o, --output FILE      the database file to write (required)\n"
    "  --fps N                resample every clip to N frames/s (default: keep the source rate)\n"
    "  --schema FILE          feature schema JSON (overrides the manifest's)\n"
    "  --mirror               also add a mirrored copy of every clip\n"
    "  --edge-rule RULE       exclude | clamp | extrapolate (overrides the manifest's)\n"
    "  --threads N            threads loading clips (default 0: all cores; at most 1024)\n"
    "  --no-animation         store features only (no skeleton, poses, root motion or contacts)\n"
    "  --quantize-rotations   store joint rotations as 16-bit integers (8 instead of 16 bytes per joint)\n"
    "  --progress             show the progress bar even when stderr is not a terminal\n"
    "  --no-progress          never show it\n";

// Redraws one line on stderr: "[#####.....]  45/145 clips  6,789 frames",
// at most every 100 ms (and always for the last clip).
void draw_progress(const BuildProgress& progress) {
  static std::chrono::steady_clock::time_point last_draw;  // the CLI's own state, one build per process
  const auto now = std::chrono::steady_clock::now();
  if (progress.clips_done != progress.clip_count && now - last_draw < std::chrono::milliseconds(100)) return;
  last_draw = now;
  const double fraction = progress.clip_count ? double(progress.clips_done) / double(progress.clip_count) : 1.0;
  std::fprintf(stderr, "\r%s %zu/%zu clips  %s frames", progress_bar(fraction).c_str(), progress.clips_done,
               progress.clip_count, thousands(progress.frames_done).c_str());
  if (progress.clips_done == progress.clip_count) std::fputc('\n', stderr);
  std::fflush(stderr);
}

}  // namespace

int run_build(Args args) {
  const auto parsed = parse_args("build", args, {"-o", "--output", "--fps", "--schema", "--edge-rule", "--threads"},
                                 {"--mirror", "--progress", "--no-progress", "--no-animation", "--quantize-rotations", "--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(kBuildUsage, stdout);
    return 0;
  }
  std::optional<std::string> output = parsed->value("-o");
  if (!output) output = parsed->value("--output");
  if (parsed->positional.size() != 1 || !output) {
    std::fputs(kBuildUsage, stderr);
    return 2;
  }
  // Before anything else: a build can take minutes, and its result would be
  // lost to a typo in the output path.
  if (Status writable = check_writable(*output); !writable) return report_error("build", writable.message(), 1);
    Result<Manifest> manifest = load_manifest_or_directory(parsed->positional[0]);
  if (!manifest.ok()) {
    std::fprintf(stderr, "mmvk build: %s\n", manifest.message().c_str());
    return 1;
  }
  if (auto fps = parsed->value("--fps")) {
    const Result<double> value = parse_positive("--fps", *fps);
    if (!value) return report_error("build", value.message(), 2);
    manifest->fps = static_cast<float>(*value);
  }
  if (auto schema_path = parsed->value("--schema")) {
    Result<FeatureSchema> schema = load_schema(*schema_path);
    if (!schema.ok()) {
      std::fprintf(stderr, "mmvk build: %s\n", schema.message().c_str());
      return 1;
    }
    manifest->schema = std::move(*schema);
  }
  if (auto rule = parsed->value("--edge-rule")) {
    Result<EdgeRule> parsed_rule = parse_edge_rule(*rule);
    if (!parsed_rule.ok()) {
      std::fprintf(stderr, "mmvk build: --edge-rule: %s\n", parsed_rule.message().c_str());
      return 2;
    }
    manifest->edge_rule = *parsed_rule;
  }
  if (parsed->has("--mirror")) {
    for (ManifestClip& clip : manifest->clips) clip.mirror = true;
  }
  {
    // Before the build: the output must not be the manifest, the schema or
    // a file the build reads.
    std::error_code ec;
    const bool folder = std::filesystem::is_directory(parsed->positional[0], ec);
    std::vector<NamedPath> paths = {{"-o", *output, true},
                                    {folder ? "the BVH folder" : "the manifest", parsed->positional[0], false}};
    if (auto schema_path = parsed->value("--schema")) paths.push_back({"--schema", *schema_path, false});
    for (const std::filesystem::path& file : manifest_input_files(*manifest)) paths.push_back({"the input", file, false});
    if (Status checked = check_command_paths(paths); !checked) return report_error("build", checked.message(), 1);
  }
  unsigned threads = 0;
  if (auto text = parsed->value("--threads")) {
    const Result<std::uint32_t> value = parse_u32("--threads", *text, 0, ThreadPool::kMaxThreads);
    if (!value) return report_error("build", value.message(), 2);
    threads = *value;
  }

  Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(threads);
  if (!pool) return report_error("build", pool.message(), 1);
  BuildOptions options;
  options.pool = pool->get();
  options.animation.enabled = !parsed->has("--no-animation");
  options.animation.warning = [](const std::string& message) {
    std::fprintf(stderr, "mmvk build: warning: %s\n", message.c_str());
  };
  if (parsed->has("--quantize-rotations")) options.animation.encoding = RotationEncoding::Quantized16;
  const bool show_progress =
      !parsed->has("--no-progress") && (parsed->has("--progress") || stderr_is_terminal());
  if (show_progress) options.progress = draw_progress;

  const auto start = std::chrono::steady_clock::now();
  Result<Database> database = build_database(*manifest, options);
  if (!database.ok()) {
    std::fprintf(stderr, "%smmvk build: %s\n", show_progress ? "\n" : "", database.message().c_str());
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Status saved = save_database(*database, *output);
  if (!saved.ok()) {
    std::fprintf(stderr, "mmvk build: %s\n", saved.message().c_str());
    return 1;
  }
  std::printf("wrote %s: %zu clips, %s frames, %u dims, %g fps (built in %.2f s, %s frames/s)\n", output->c_str(),
              database->clips().size(), thousands(database->frame_count()).c_str(), database->dims(),
              double(database->fps()), seconds,
              thousands(static_cast<unsigned long long>(seconds > 0 ? database->frame_count() / seconds : 0)).c_str());
  return 0;
}

}  // namespace mmvk::cli
