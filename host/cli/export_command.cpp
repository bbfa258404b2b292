// mmvk export: the normalized feature matrix as raw float32 plus a JSON
// sidecar describing its layout, for analysis and training outside mmvk.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "animation_report.hpp"
#include "commands.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/hash.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kExportDescription =
    "Writes the normalized feature matrix as raw little-endian float32, row-major [frames x dims], and a JSON "
    "sidecar (default: <out>.json) with dims, fps, channel names and groups, per-dimension names, offsets, scales "
    "and weights (raw = normalized * scale + offset; scale already includes 1 / weight), tag names, clip ranges and "
    "the per-frame flags (1 = do_not_use, 2 = block_transition, 4 = edge_excluded).\n"
    "\n"
    "--animation anim.f32 writes the animation section the same way (float32 [frames x columns] and anim.f32.json "
    "naming the columns, the skeleton and the clips); either --features or --animation may be given alone.\n"
    "\n"
    "A device or FIFO output (--features /dev/stdout) is written in place; its sidecar must then be named with "
    "--sidecar (--animation needs a file).";

struct ExportArgs {
  std::string database;
  std::optional<std::string> features;
  std::optional<std::string> sidecar;  // as given
  std::optional<std::string> animation;
  std::string sidecar_path;  // as written: --sidecar, else --features + .json
};

nlohmann::json sidecar(const Database& db, const std::string& source, const std::string& features_path) {
  const FeatureSchema& schema = db.schema();
  nlohmann::json out;
  out["format"] = "float32 little-endian, row-major [frames x dims], normalized";
  out["features"] = std::filesystem::path(features_path).filename().string();
  out["source"] = source;
  out["frames"] = db.frame_count();
  out["dims"] = db.dims();
  out["fps"] = db.fps();
  out["content_hash"] = hash_hex(db.content_hash());
  out["channels"] = nlohmann::json::array();
  std::vector<std::uint32_t> groups;
  std::vector<float> weights;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    nlohmann::json ch = {{"name", channel.name},       {"kind", channel_kind_name(channel.kind)},
                         {"normalization", normalization_name(channel.normalization)},
                         {"weight", channel.weight},   {"offset", schema.offset(c)},
                         {"dims", channel.dims()}};
    if (!channel.bone.empty()) ch["bone"] = channel.bone;
    if (!channel.second_bone.empty()) ch["second_bone"] = channel.second_bone;
    if (!channel.offsets_seconds.empty()) ch["offsets_seconds"] = channel.offsets_seconds;
    if (!channel.curves.empty()) {
      ch["curves"] = channel.curves;
      ch["window_seconds"] = channel.window_seconds;
    }
    out["channels"].push_back(std::move(ch));
    for (std::uint32_t d = 0; d < channel.dims(); ++d) {
      groups.push_back(static_cast<std::uint32_t>(c));
      weights.push_back(channel.weight);
    }
  }
  std::vector<std::string> names;
  std::vector<float> offsets;
  std::vector<float> scales;
  for (std::uint32_t d = 0; d < db.dims(); ++d) {
    names.push_back(schema.dim_name(d));
    offsets.push_back(db.normalization()[d].offset);
    scales.push_back(db.normalization()[d].scale);
  }
  out["dim_names"] = names;
  out["groups"] = groups;
  out["offsets"] = offsets;
  out["scales"] = scales;
  out["weights"] = weights;
  out["tags"] = std::vector<std::string>(db.tag_names().begin(), db.tag_names().end());
  out["clips"] = nlohmann::json::array();
  for (const Clip& clip : db.clips()) {
    std::vector<std::string> tags;
    for (std::size_t t = 0; t < db.tag_names().size(); ++t) {
      if (clip.tags & (TagMask{1} << t)) tags.push_back(db.tag_names()[t]);
    }
    out["clips"].push_back({{"name", clip.name}, {"source", clip.source}, {"first_frame", clip.first_frame},
                            {"frame_count", clip.frame_count}, {"loop", clip.loop}, {"mirrored", clip.mirrored},
                            {"cost_multiplier", clip.cost_multiplier}, {"cost_bias", clip.cost_bias}, {"tags", tags}});
  }
  out["frame_flags"] = std::vector<std::uint32_t>(db.frame_flags().begin(), db.frame_flags().end());
  return out;
}

// Returns the exit code when the export must not run (help, usage errors).
std::optional<int> parse_export_args(Args args, ExportArgs& out) {
  CommandLine cli(kExportCommand, kExportDescription);
  cli.positional("db.mmdb", out.database);
  cli.text("--features", out.features, "FILE", "the feature matrix to write (float32)");
  cli.text("--sidecar", out.sidecar, "FILE", "its JSON sidecar (default: the --features file + .json)");
  cli.text("--animation", out.animation, "FILE", "the animation section to write (float32), and FILE.json beside it");
  if (const std::optional<int> exit_code = cli.parse(args)) return exit_code;
  if (!out.features && !out.animation) return cli.usage_error();
  if (out.features) out.sidecar_path = out.sidecar.value_or(*out.features + ".json");
  return std::nullopt;
}

// Before any work: an output that is the database, or another output,
// would destroy it.
Status check_paths(const ExportArgs& args) {
  std::vector<NamedPath> paths = {{"the database", args.database, false}};
  if (args.features) {
    paths.push_back({"--features", *args.features, true});
    paths.push_back({args.sidecar ? "--sidecar" : "the sidecar (--features + .json)", args.sidecar_path, true});
  }
  if (args.animation) {
    paths.push_back({"--animation", *args.animation, true});
    paths.push_back({"the animation sidecar (--animation + .json)", *args.animation + ".json", true});
  }
  // A default sidecar beside a device or FIFO (--features /dev/null) would
  // be a new file in /dev: it must be named.
  if (args.features && !args.sidecar && is_stream_path(*args.features)) {
    return make_error("--features " + *args.features + " is a device or FIFO: name the JSON sidecar with --sidecar");
  }
  if (args.animation && is_stream_path(*args.animation)) {
    return make_error("--animation " + *args.animation + " is a device or FIFO: its sidecar would be " +
                      *args.animation + ".json beside it; write to a file");
  }
  return check_command_paths(paths);
}

Status write_features(const Database& db, const ExportArgs& args) {
  // The sidecar's text exists before any file is written; names with
  // invalid UTF-8 are replaced (U+FFFD), never thrown.
  const std::string sidecar_text =
      sidecar(db, args.database, *args.features).dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  MMVK_TRY(write_f32_rows(*args.features, db.features()));
  MMVK_TRY(write_file_atomically(args.sidecar_path, sidecar_text));
  std::printf("wrote %s (%u frames x %u dims, float32) and %s\n", args.features->c_str(), db.frame_count(), db.dims(),
              args.sidecar_path.c_str());
  return {};
}

int run_export(Args args, const char*) {
  ExportArgs parsed;
  if (const std::optional<int> exit_code = parse_export_args(args, parsed)) return *exit_code;
  if (Status checked = check_paths(parsed); !checked) return report_error("export", checked.message(), 1);
  Result<Database> db = load_database(parsed.database);
  if (!db.ok()) return report_error("export", db.message(), 1);
  if (const std::optional<std::string>& animation = parsed.animation) {
    if (Status written = export_animation(*db, parsed.database, *animation, *animation + ".json"); !written.ok()) {
      return report_error("export", written.message(), 1);
    }
    std::printf("wrote %s (%u frames, float32) and %s.json\n", animation->c_str(), db->frame_count(),
                animation->c_str());
  }
  if (parsed.features) {
    if (Status written = write_features(*db, parsed); !written.ok()) return report_error("export", written.message(), 1);
  }
  return 0;
}

}  // namespace

const Command kExportCommand{"export", "db.mmdb --features out.f32", "the normalized feature matrix + JSON sidecar",
                             run_export};

}  // namespace mmvk::cli
