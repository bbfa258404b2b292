// mmvk inspect: what is in a database file.
#include <cinttypes>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/database/gait_coverage.hpp"
#include "mmvk/common/hash.hpp"
#include "mmvk/common/input_text.hpp"
#include "mmvk/features/normalization.hpp"
#include "animation_report.hpp"
#include "units_report.hpp"

namespace mmvk::cli {

namespace {

// Names are shown with the input-text rule (mmvk/common/input_text.hpp); a path
// the user typed and the joined lists are longer than one name, so they get
// bounds of their own.
constexpr std::size_t kMaxPathBytes = 4096;
constexpr std::size_t kMaxListBytes = 1024;

constexpr const char* kInspectDescription =
    "Prints the database's frames, clips, fps, tags, frame flag counts, the metres per file unit the import used, "
    "the skeleton's standing height, the walk and run speeds the crowd measures, what the data can do (stand, start, "
    "stop, the speed bands it covers: the measured gait tags), and, per channel and dimension, the "
    "normalization offset and scale and the raw (unnormalized) mean, std, min and max.";

std::string tag_list(const Database& db, TagMask mask) {
  std::string out;
  for (std::size_t t = 0; t < db.tag_names().size(); ++t) {
    if (mask & (TagMask{1} << t)) out += (out.empty() ? "" : ",") + db.tag_names()[t];
  }
  return out.empty() ? "-" : out;
}

struct RawDimStats {
  double mean, std, min, max;
};

// Statistics of the raw features, recovered from the normalized matrix
// (raw = normalized * scale + offset; scale > 0 keeps min and max in place).
std::vector<RawDimStats> raw_statistics(const Database& db) {
  const std::vector<DimStatistics> stats = compute_statistics(db.features(), db.dims());
  std::vector<RawDimStats> raw(db.dims());
  for (std::uint32_t d = 0; d < db.dims(); ++d) {
    const double offset = db.normalization()[d].offset;
    const double scale = db.normalization()[d].scale;
    raw[d] = {stats[d].mean * scale + offset, stats[d].std * scale, stats[d].min * scale + offset,
              stats[d].max * scale + offset};
  }
  return raw;
}

// Frame and clip counts: flags, tags, mirrored and looping clips.
struct Counts {
  std::uint64_t do_not_use = 0, block = 0, edge = 0, candidates = 0;
  std::size_t mirrored = 0, looping = 0;
  std::vector<std::uint64_t> tag_frames;  // per tag
};

Counts count(const Database& db) {
  Counts counts;
  for (std::uint32_t flags : db.frame_flags()) {
    counts.do_not_use += (flags & kFrameDoNotUse) != 0;
    counts.block += (flags & kFrameBlockTransition) != 0;
    counts.edge += (flags & kFrameEdgeExcluded) != 0;
    counts.candidates += (flags & (kFrameDoNotUse | kFrameEdgeExcluded)) == 0;
  }
  for (const Clip& clip : db.clips()) {
    counts.mirrored += clip.mirrored;
    counts.looping += clip.loop;
  }
  // Per frame: tags on time ranges (manifest tag_ranges) cover part of a clip.
  counts.tag_frames.assign(db.tag_names().size(), 0);
  for (const TagMask tags : db.frame_tags()) {
    for (std::size_t t = 0; t < counts.tag_frames.size(); ++t) counts.tag_frames[t] += (tags >> t) & 1u;
  }
  return counts;
}

nlohmann::json channels_json(const Database& db, const std::vector<RawDimStats>& raw) {
  const FeatureSchema& schema = db.schema();
  nlohmann::json channels = nlohmann::json::array();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    nlohmann::json ch = {{"name", channel.name}, {"kind", channel_kind_name(channel.kind)},
                         {"normalization", normalization_name(channel.normalization)}, {"weight", channel.weight},
                         {"offset", schema.offset(c)}, {"dims", channel.dims()}};
    ch["dimensions"] = nlohmann::json::array();
    for (std::uint32_t d = schema.offset(c); d < schema.offset(c) + channel.dims(); ++d) {
      ch["dimensions"].push_back({{"name", schema.dim_name(d)}, {"offset", db.normalization()[d].offset},
                                  {"scale", db.normalization()[d].scale}, {"mean", raw[d].mean},
                                  {"std", raw[d].std}, {"min", raw[d].min}, {"max", raw[d].max}});
    }
    channels.push_back(std::move(ch));
  }
  return channels;
}

// The measured gait tags' coverage (mmvk/database/gait_coverage.hpp); null when the
// database has none.
nlohmann::json gait_json(const Database& db) {
  const GaitCoverage coverage = measure_gait_coverage(db);
  if (!coverage.measured) return nullptr;
  const GaitBandParams& params = *db.gait_bands();
  nlohmann::json bands = nlohmann::json::object();
  for (std::size_t b = 0; b < kGaitBandCount; ++b) {
    bands[std::string(kGaitTagNames[b].substr(kGaitTagPrefix.size()))] = coverage.band_frames[b];
  }
  return {{"capabilities", gait_capabilities(coverage)},
          {"stands", coverage.can_stand()},
          {"longest_stand_s", coverage.longest_stand_seconds},
          {"stand_loop", coverage.stand_loop},
          {"band_frames", bands},
          {"start_frames", coverage.start_frames},
          {"stop_frames", coverage.stop_frames},
          {"stand_both_feet_frames", coverage.has_contacts ? nlohmann::json(coverage.stand_both_feet_frames) : nullptr},
          {"moving_mps_p5", coverage.moving_p95_mps > 0.0f ? nlohmann::json(coverage.moving_p5_mps) : nullptr},
          {"moving_mps_p95", coverage.moving_p95_mps > 0.0f ? nlohmann::json(coverage.moving_p95_mps) : nullptr},
          {"thresholds", {{"walk_from_mps", params.walk_from_mps}, {"jog_from_mps", params.jog_from_mps},
                          {"run_from_mps", params.run_from_mps}, {"hysteresis", params.hysteresis},
                          {"smoothing_seconds", params.smoothing_seconds},
                          {"transition_seconds", params.transition_seconds}}}};
}

void print_json(const Database& db, const std::string& path, const Counts& counts) {
  nlohmann::json out;
  out["file"] = path;
  out["frames"] = db.frame_count();
  out["dims"] = db.dims();
  out["fps"] = db.fps();
  out["content_hash"] = hash_hex(db.content_hash());
  out["flags"] = {{"do_not_use", counts.do_not_use}, {"block_transition", counts.block},
                  {"edge_excluded", counts.edge}, {"candidates", counts.candidates}};
  out["tags"] = nlohmann::json::array();
  for (std::size_t t = 0; t < counts.tag_frames.size(); ++t) {
    out["tags"].push_back({{"name", db.tag_names()[t]}, {"frames", counts.tag_frames[t]}});
  }
  out["channels"] = channels_json(db, raw_statistics(db));
  out["animation"] = animation_json(db);
  out["units"] = units_json(db);
  out["gait"] = gait_json(db);
  out["clips"] = nlohmann::json::array();
  for (const Clip& clip : db.clips()) {
    out["clips"].push_back({{"name", clip.name}, {"source", clip.source}, {"first_frame", clip.first_frame},
                            {"frame_count", clip.frame_count}, {"loop", clip.loop}, {"mirrored", clip.mirrored},
                            {"cost_multiplier", clip.cost_multiplier}, {"cost_bias", clip.cost_bias},
                            {"tags", tag_list(db, clip.tags)}});
  }
  // JSON escapes control characters itself; invalid UTF-8 in a name is
  // replaced (U+FFFD) rather than thrown as an exception.
  std::printf("%s\n", out.dump(2, ' ', false, nlohmann::json::error_handler_t::replace).c_str());
}

void print_summary(const Database& db, const std::string& path, const Counts& counts) {
  std::printf("%s: %s (%.1f s), %s (%zu mirrored, %zu looping), %u dims, %g fps\n", printable_text(path, kMaxPathBytes).c_str(),
              counted(db.frame_count(), "frame").c_str(), db.frame_count() / double(db.fps()),
              counted(db.clips().size(), "clip").c_str(), counts.mirrored, counts.looping, db.dims(), double(db.fps()));
  std::printf("content hash: %s\n", hash_hex(db.content_hash()).c_str());
  print_animation(db);
  print_units(db);
  const GaitCoverage coverage = measure_gait_coverage(db);
  std::printf("can do: %s\n", gait_capabilities(coverage).c_str());
  if (coverage.measured) std::printf("%s\n", describe_gait_coverage(coverage, db.gait_bands()).c_str());
  std::printf("frame flags: %s do_not_use, %s block_transition, %s edge_excluded; %s candidate frames\n",
              thousands(counts.do_not_use).c_str(), thousands(counts.block).c_str(), thousands(counts.edge).c_str(),
              thousands(counts.candidates).c_str());
  const std::vector<std::uint64_t>& tag_frames = counts.tag_frames;
  std::printf("tags (%zu):", tag_frames.size());
  for (std::size_t t = 0; t < tag_frames.size(); ++t) {
    std::printf(" %s (%s frames)%s", printable_text(db.tag_names()[t]).c_str(), thousands(tag_frames[t]).c_str(),
                t + 1 < tag_frames.size() ? "," : "");
  }
  std::printf("%s\n", tag_frames.empty() ? " none" : "");
}

// What a channel reads: its bones, curves or trajectory offsets.
std::string channel_detail(const FeatureChannel& channel) {
  std::string detail = channel.bone;
  if (!channel.second_bone.empty()) detail += " -> " + channel.second_bone;
  if (!channel.curves.empty()) {
    detail = "+-" + std::to_string(channel.window_seconds).substr(0, 5) + " s:";
    for (const std::string& curve : channel.curves) detail += " " + curve;
  }
  if (uses_trajectory_offsets(channel.kind)) {
    detail = "offsets (s):";
    for (float t : channel.offsets_seconds) detail += " " + std::to_string(t).substr(0, 5);
  }
  return detail;
}

void print_channels(const Database& db) {
  const std::vector<RawDimStats> raw = raw_statistics(db);
  const FeatureSchema& schema = db.schema();
  std::printf("\nchannels (raw values: metres, m/s; normalized = (raw - offset) / scale):\n");
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    std::printf("  %-24s %-20s %-12s weight %-6g %s\n", printable_text(channel.name).c_str(),
                channel_kind_name(channel.kind).data(), normalization_name(channel.normalization).data(),
                double(channel.weight), printable_text(channel_detail(channel), kMaxListBytes).c_str());
    std::printf("    %-32s %10s %10s %10s %10s %10s %10s\n", "dimension", "offset", "scale", "mean", "std", "min", "max");
    for (std::uint32_t d = schema.offset(c); d < schema.offset(c) + channel.dims(); ++d) {
      std::printf("    %-32s %10.4f %10.4f %10.4f %10.4f %10.4f %10.4f\n", printable_text(schema.dim_name(d)).c_str(),
                  double(db.normalization()[d].offset), double(db.normalization()[d].scale), raw[d].mean, raw[d].std,
                  raw[d].min, raw[d].max);
    }
  }
}

void print_clips(const Database& db) {
  std::printf("\nclips:\n  %5s  %-40s %8s %8s  %-5s %-8s %6s %6s  %s\n", "#", "name", "first", "frames", "loop",
              "mirrored", "mult", "bias", "tags");
  for (std::size_t c = 0; c < db.clips().size(); ++c) {
    const Clip& clip = db.clips()[c];
    std::printf("  %5zu  %-40s %8u %8u  %-5s %-8s %6g %6g  %s\n", c, printable_text(clip.name).c_str(), clip.first_frame,
                clip.frame_count, clip.loop ? "yes" : "no", clip.mirrored ? "yes" : "no", double(clip.cost_multiplier),
                double(clip.cost_bias), printable_text(tag_list(db, clip.tags), kMaxListBytes).c_str());
  }
}

int run_inspect(Args args, const char*) {
  std::string path;
  bool json = false;
  CommandLine cli(kInspectCommand, kInspectDescription);
  cli.positional("db.mmdb", path);
  cli.flag("--json", json, "the same as one JSON object on stdout");
  if (const std::optional<int> exit_code = cli.parse(args)) return *exit_code;
  Result<Database> loaded = load_database(path);
  if (!loaded.ok()) return report_error("inspect", loaded.message(), 1);
  const Counts counts = count(*loaded);
  if (json) {
    print_json(*loaded, path, counts);
  } else {
    print_summary(*loaded, path, counts);
    print_channels(*loaded);
    print_clips(*loaded);
  }
  return 0;
}

}  // namespace

const Command kInspectCommand{"inspect", "db.mmdb", "clips, frames, channel statistics and tags", run_inspect};

}  // namespace mmvk::cli
