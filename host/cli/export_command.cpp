// mmvk export: the normalized feature matrix as raw float32 plus a JSON
// sidecar describing its layout, for analysis and training outside mmvk.
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "animation_report.hpp"
#include "commands.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/hash.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kExportUsage =
    "usage: mmvk export db.mmdb --features out.f32 [--sidecar out.f32.json] [--animation anim.f32]\n"
    "\n"
    "Writes the normalized feature matrix as raw little-endian float32, row-major\n"
    "[frames x dims], and a JSON sidecar (default: <out>.json) with dims, fps,\n"
    "channel names and groups, per-dimension names, offsets, scales and weights\n"
    "(raw = normalized * scale + offset; scale already includes 1 / weight), tag\n"
    "names, clip ranges and the per-frame flags (1 = do_not_use,\n"
    "2 = block_transition, 4 = edge_excluded).\n"
    "\n"
    "--animation anim.f32 writes the animation section the same way (float32\n"
    "[frames x columns] and anim.f32.json naming the columns, the skeleton and\n"
    "the clips); either --features or --animation may be given alone.\n"
    "\n"
    "A device or FIFO output (--features /dev/stdout) is written in place; its\n"
    "sidecar must then be named with --sidecar (--animation needs a file).\n";

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

}  // namespace

int run_export(Args args) {
  const auto parsed = parse_args("export", args, {"--features", "--sidecar", "--animation"}, {"--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(kExportUsage, stdout);
    return 0;
  }
  const std::optional<std::string> features = parsed->value("--features");
  const std::optional<std::string> animation = parsed->value("--animation");
  if (parsed->positional.size() != 1 || (!features && !animation)) {
    std::fputs(kExportUsage, stderr);
    return 2;
  }
  const std::string sidecar_path = features ? parsed->value("--sidecar").value_or(*features + ".json") : std::string();
  // Before any work: an output that is the database, or another output,
  // would destroy it.
  std::vector<NamedPath> paths = {{"the database", parsed->positional[0], false}};
  if (features) {
    paths.push_back({"--features", *features, true});
    paths.push_back({parsed->value("--sidecar") ? "--sidecar" : "the sidecar (--features + .json)", sidecar_path, true});
  }
  if (animation) {
    paths.push_back({"--animation", *animation, true});
    paths.push_back({"the animation sidecar (--animation + .json)", *animation + ".json", true});
  }
  // A default sidecar beside a device or FIFO (--features /dev/null) would
  // be a new file in /dev: it must be named.
  if (features && !parsed->value("--sidecar") && is_stream_path(*features)) {
    return report_error("export", "--features " + *features + " is a device or FIFO: name the JSON sidecar with --sidecar", 1);
  }
  if (animation && is_stream_path(*animation)) {
    return report_error("export", "--animation " + *animation + " is a device or FIFO: its sidecar would be " +
                                      *animation + ".json beside it; write to a file", 1);
  }
  if (Status checked = check_command_paths(paths); !checked) return report_error("export", checked.message(), 1);
  Result<Database> db = load_database(parsed->positional[0]);
  if (!db.ok()) {
    std::fprintf(stderr, "mmvk export: %s\n", db.message().c_str());
    return 1;
  }
  if (animation) {
    if (Status written = export_animation(*db, parsed->positional[0], *animation, *animation + ".json"); !written.ok()) {
      std::fprintf(stderr, "mmvk export: %s\n", written.message().c_str());
      return 1;
    }
    std::printf("wrote %s (%u frames, float32) and %s.json\n", animation->c_str(), db->frame_count(), animation->c_str());
    if (!features) return 0;
  }
  // The sidecar's text exists before any file is written; names with
  // invalid UTF-8 are replaced (U+FFFD), never thrown.
  const std::string sidecar_text =
      sidecar(*db, parsed->positional[0], *features).dump(1, ' ', false, nlohmann::json::error_handler_t::replace) +
      "\n";
  Status written = write_f32_rows(*features, db->features());
  if (written.ok()) written = write_file_atomically(sidecar_path, sidecar_text);
  if (!written.ok()) {
    std::fprintf(stderr, "mmvk export: %s\n", written.message().c_str());
    return 1;
  }
  std::printf("wrote %s (%u frames x %u dims, float32) and %s\n", features->c_str(), db->frame_count(), db->dims(),
              sidecar_path.c_str());
  return 0;
}

}  // namespace mmvk::cli
