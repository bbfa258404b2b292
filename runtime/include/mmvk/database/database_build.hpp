// Manifest -> Database: load every clip (parse, import, resample, mirror),
// extract raw features with the schema, normalize them over the whole
// database, and assemble clips, tags and per-frame flags.
//
// Rules:
//   - Frame rate: the manifest's fps (or the CLI's --fps) resamples every clip;
//     without it the database keeps the source rate, and clips with different
//     source rates are an error naming two files that disagree.
//   - Mirroring: a clip with mirror = true is followed by its mirrored copy,
//     a separate clip named "<name>_mirrored" with Clip::mirrored set and the
//     same tags, flags and costs. Joints pair by mirror_pairs() with the
//     manifest's mirror_bones over the name heuristics; custom (sidecar)
//     channel values follow the manifest's mirror_map (copied unchanged
//     without an entry).
//   - Edge rule (non-looping clips): a frame whose furthest trajectory offset
//     (round(max offset_seconds x fps) frames ahead) lies past the clip's last
//     frame is flagged kFrameEdgeExcluded with EdgeRule::Exclude, and kept as
//     an ordinary frame with clamped trajectory features with
//     EdgeRule::Clamp, or with extrapolated ones with EdgeRule::Extrapolate
//     (which flags only a clip's last kExtrapolateEndSeconds and frames whose
//     phase window crosses an edge; see manifest.hpp). Looping clips wrap and
//     never get the flag.
//   - Time ranges: frame f of a clip is in [begin, end) seconds when
//     begin <= f / fps < end; do_not_use sets kFrameDoNotUse,
//     block_transition sets kFrameBlockTransition; a frame in a tag range
//     carries its tag, and cost ranges multiply its multiplier and add to
//     its bias (manifest.hpp). Tag and cost ranges must lie inside their
//     clip, else the error names the manifest and the field
//     ("db.json: clips[2].tag_ranges.jump[0]: ... lies outside the clip").
//     With any of them, the database stores per-frame tags and costs
//     (DatabaseParts::frame_tags and the others), which every backend reads.
//   - Gait tags: with gait_bands enabled (the default), every frame carries
//     the measured tags of gait_bands.hpp (its speed band, and start or stop
//     near a stand), numbered after the manifest's own tags, and the
//     database keeps the parameters (Database::gait_bands). A manifest tag
//     that begins with "gait:" is an error naming the field.
//   - Normalization statistics are taken over every frame of the database
//     (normalization.hpp); tags are numbered in order of first appearance.
//   - Skeletons may differ between clips as long as the schema's bones
//     resolve on each (find_bone).
//   - Physically impossible motion is an error naming the clip, frame and
//     channel: a feature beyond its kind's plausible_limit (channel_kinds.hpp:
//     positions kMaxPlausiblePosition metres from the character, velocities
//     kMaxPlausibleSpeed m/s). One corrupt value (a 1e30 in a BVH) would
//     otherwise set its channel's normalization scale and flatten that
//     channel for every other frame.
//   - A database in which no frame can ever be a result (every frame
//     do-not-use or edge-excluded) is an error.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

struct BuildProgress {
  std::size_t clips_done = 0;     // manifest clips loaded so far
  std::size_t clip_count = 0;     // manifest clips in all
  std::uint64_t frames_done = 0;  // database frames produced so far (mirrored copies included)
};

// The animation section (animation_data.hpp): on by default. It needs one
// skeleton (joint names and parents) across all clips; when the clips'
// skeletons differ (which the features allow), the database is built
// without the section and `warning` (when set) receives a message naming two
// clips that differ.
struct AnimationBuildOptions {
  bool enabled = true;  // false = features only (mmvk build --no-animation)
  std::function<void(const std::string&)> warning;
  RotationEncoding encoding = RotationEncoding::Float32;  // how the .mmdb file keeps rotations
};

struct BuildOptions {
  // Called after each manifest clip is processed. Calls are serialized but
  // may come from the pool's worker threads.
  std::function<void(const BuildProgress&)> progress;
  // Clips are loaded and featurized in parallel on this pool when given.
  ThreadPool* pool = nullptr;
  AnimationBuildOptions animation;
};

Result<Database> build_database(const Manifest& manifest, const BuildOptions& options = {});

// The lower-level entry: clips already in memory (tests, hosts with their own
// importer). `meta.file` only names the clip in messages and Clip::source;
// `meta.mirror` is ignored (pass mirrored motions yourself, with mirrored =
// true). Every motion must have the same fps, which the database keeps.
struct MotionClip {
  ManifestClip meta;
  Motion motion;
  std::vector<std::vector<float>> custom;  // one [frames x dims] array per Custom channel, schema order
  bool mirrored = false;
};

struct MotionBuildSettings {
  FeatureSchema schema = default_schema();
  CharacterRootOptions character_root;
  EdgeRule edge_rule = EdgeRule::Exclude;
  AnimationBuildOptions animation;
  FootContactParams contacts;  // the animation's contacts and the foot_contact channel (Manifest::contacts)
  GaitBandParams gait_bands;   // the measured gait tags (Manifest::gait_bands)
};

Result<Database> build_database_from_motions(std::span<const MotionClip> clips, const MotionBuildSettings& settings);

}  // namespace mmvk
