// mmvk build: manifest (or folder of BVH) -> .mmdb database file.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kBuildDescription =
    "Builds a motion matching database from BVH motion capture. A BVH file or a folder of BVH is built with the "
    "default schema and options; a JSON manifest names clips, tags, flags and options (see runtime/include/mmvk/database/manifest.hpp).";

// The command line, parsed: overrides of the manifest and build options.
struct BuildArgs {
  std::string input;  // manifest, folder of BVH or one BVH file
  std::string output;
  std::optional<double> fps;
  std::optional<std::string> schema;
  std::optional<EdgeRule> edge_rule;
  bool mirror = false;
  unsigned threads = 0;
  bool no_animation = false;
  bool quantize_rotations = false;
  bool always_progress = false;
  bool no_progress = false;
};

// Returns the exit code when the build must not run (help, usage errors).
std::optional<int> parse_build_args(Args args, BuildArgs& out) {
  CommandLine cli(kBuildCommand, kBuildDescription);
  cli.positional("input", out.input);
  cli.text("-o,--output", out.output, "FILE", "the database file to write (required)")->required();
  cli.positive("--fps", out.fps, "N", "resample every clip to N frames/s (default: keep the source rate)");
  cli.text("--schema", out.schema, "FILE", "feature schema JSON (overrides the manifest's)");
  cli.flag("--mirror", out.mirror, "also add a mirrored copy of every clip");
  cli.value("--edge-rule", out.edge_rule, "RULE", "exclude | clamp | extrapolate (overrides the manifest's)",
            [](const std::string& text) -> Result<EdgeRule> {
              Result<EdgeRule> rule = parse_edge_rule(text);
              if (!rule) return make_error("--edge-rule: " + rule.message());
              return rule;
            });
  cli.integer("--threads", out.threads, "N", "threads loading clips (default 0: all cores; at most 1024)", 0,
              ThreadPool::kMaxThreads);
  cli.flag("--no-animation", out.no_animation, "store features only (no skeleton, poses, root motion or contacts)");
  cli.flag("--quantize-rotations", out.quantize_rotations,
           "store joint rotations as 16-bit integers (8 instead of 16 bytes per joint)");
  cli.flag("--progress", out.always_progress, "show the progress bar even when stderr is not a terminal");
  cli.flag("--no-progress", out.no_progress, "never show it");
  return cli.parse(args);
}

// The manifest (or the folder's default one) with the command line's
// overrides applied.
Result<Manifest> manifest_with_overrides(const BuildArgs& args) {
  MMVK_ASSIGN_OR_RETURN(Manifest manifest, load_manifest_or_directory(args.input));
  if (args.fps) manifest.fps = static_cast<float>(*args.fps);
  if (args.schema) {
    MMVK_ASSIGN_OR_RETURN(manifest.schema, load_schema(*args.schema));
  }
  if (args.edge_rule) manifest.edge_rule = *args.edge_rule;
  if (args.mirror) {
    for (ManifestClip& clip : manifest.clips) clip.mirror = true;
  }
  return manifest;
}

// Before the build: the output must not be the manifest, the schema or a
// file the build reads.
Status check_paths(const BuildArgs& args, const Manifest& manifest) {
  std::error_code ec;
  const bool folder = std::filesystem::is_directory(args.input, ec);
  std::vector<NamedPath> paths = {{"-o", args.output, true}};
  // A motion file is its manifest's one clip, and is named as an input below.
  if (folder || !is_motion_path(args.input)) {
    paths.push_back({folder ? "the motion folder" : "the manifest", args.input, false});
  }
  if (args.schema) paths.push_back({"--schema", *args.schema, false});
  for (const std::filesystem::path& file : manifest_input_files(manifest)) paths.push_back({"the input", file, false});
  return check_command_paths(paths);
}

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

int run_build(Args args, const char*) {
  BuildArgs parsed;
  if (const std::optional<int> exit_code = parse_build_args(args, parsed)) return *exit_code;
  // Before anything else: a build can take minutes, and its result would be
  // lost to a typo in the output path.
  if (Status writable = check_writable(parsed.output); !writable) return report_error("build", writable.message(), 1);
  Result<Manifest> manifest = manifest_with_overrides(parsed);
  if (!manifest) return report_error("build", manifest.message(), 1);
  if (Status checked = check_paths(parsed, *manifest); !checked) return report_error("build", checked.message(), 1);

  Result<std::unique_ptr<ThreadPool>> pool = ThreadPool::create(parsed.threads);
  if (!pool) return report_error("build", pool.message(), 1);
  BuildOptions options;
  options.pool = pool->get();
  options.animation.enabled = !parsed.no_animation;
  options.animation.warning = [](const std::string& message) {
    std::fprintf(stderr, "mmvk build: warning: %s\n", message.c_str());
  };
  if (parsed.quantize_rotations) options.animation.encoding = RotationEncoding::Quantized16;
  const bool show_progress = !parsed.no_progress && (parsed.always_progress || stderr_is_terminal());
  if (show_progress) options.progress = draw_progress;

  const auto start = std::chrono::steady_clock::now();
  Result<Database> database = build_database(*manifest, options);
  if (!database.ok()) {
    std::fprintf(stderr, "%smmvk build: %s\n", show_progress ? "\n" : "", database.message().c_str());
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  Status saved = save_database(*database, parsed.output);
  if (!saved.ok()) {
    std::fprintf(stderr, "mmvk build: %s\n", saved.message().c_str());
    return 1;
  }
  std::printf("wrote %s: %s, %s, %u dims, %g fps (built in %.2f s, %s frames/s)\n", parsed.output.c_str(),
              counted(database->clips().size(), "clip").c_str(), counted(database->frame_count(), "frame").c_str(),
              database->dims(),
              double(database->fps()), seconds,
              thousands(static_cast<unsigned long long>(seconds > 0 ? database->frame_count() / seconds : 0)).c_str());
  return 0;
}

}  // namespace

const Command kBuildCommand{"build", "<manifest.json | bvh-dir | file.bvh> -o db.mmdb", "build a database from BVH motion capture",
                            run_build};

}  // namespace mmvk::cli
