// The database manifest: which BVH clips go into a database, with their tags,
// flags and cost adjustments, and the database-level build options.
//
// JSON form (every field but "clips" optional; unknown fields are errors):
// {
//   "schema": "schema.json" | { "channels": [...] },   // default: default_schema()
//   "fps": 30,                 // resample every clip to this rate; default: keep the source rate
//   "import": { "metres_per_unit": 0.01, "up_axis": "y" | "z" },
//   "character_root": { "source_bone": "@hips", "facing_smoothing_seconds": 0.5 },
//   "edge_rule": "exclude" | "clamp" | "extrapolate",    // default "exclude"
//   "mirror": false,           // add a mirrored copy of every clip
//   "mirror_bones": [["LeftFoot", "RightFoot"], ["@left_hand", "Hand_R"]],
//                              // left/right pairs that override the name heuristics
//   "mirror_map": { "phase": { "swap": [[0, 2], [1, 3]], "negate": [4] } },
//                              // how a custom (sidecar) channel's dims mirror
//   "contacts": { "enter_speed": 0.1, "exit_speed": 0.2, ... },
//                              // foot contact detection: any FootContactParams
//                              // field by name (foot_contacts.hpp; defaults there)
//   "gait_bands": { "walk_from_mps": 0.15, "jog_from_mps": 2.0, "run_from_mps": 3.0,
//                   "hysteresis": 0.1, "smoothing_seconds": 0.25, "transition_seconds": 1.0,
//                   "enabled": true },
//                              // the measured gait tags: any GaitBandParams field
//                              // by name (gait_bands.hpp; defaults there)
//   "crowd": { "correction_half_life": 0.07, ... },
//                              // settings a crowd host tuned for this data, kept in
//                              // the database as they are (Database::crowd_settings)
//   "clips": [
//     { "file": "walk.bvh",    // relative paths are relative to the manifest's folder;
//                              // .bvh, or .fbx/.gltf/.glb/.dae through assimp (scene_import.hpp)
//       "animation": "Walk",   // scene files: only this animation (default: each one, a clip apiece)
//       "range": [0.5, 1.4],   // only this part of the file, seconds (default: all of it)
//       "name": "walk",        // default: the file name without extension
//       "tags": ["walk"], "loop": false, "mirror": false,
//       "cost_multiplier": 1.0, "cost_bias": 0.0,
//       "do_not_use": [[0.0, 0.5]],         // [begin, end) in seconds
//       "block_transition": [[2.0, 2.5]],
//       "tag_ranges": { "jump": [[1.0, 1.6]] },   // tags on time ranges only
//       "cost_ranges": [ { "range": [1.0, 1.6], "cost_multiplier": 2.0, "cost_bias": 0.1 } ] }
//   ]
// }
// A frame's tags are its clip's tags plus those of every tag range it lies
// in; its cost multiplier is the clip's times those of the cost ranges it
// lies in, its bias the clip's plus theirs. A tag or cost range must lie
// inside its clip (begin before the clip's end, end at most one frame past
// it, at least one frame covered); the build checks that, since only it
// knows the clip's length, and names the manifest and field.
// Error messages name the manifest and the field: "db.json: clips[2].loop:
// expected true or false".
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/import/character.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/database/gait_bands.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// What happens to frames whose furthest trajectory offset runs past the end of
// a non-looping clip: Exclude flags them kFrameEdgeExcluded (they are never
// search results; their features clamp to the last frame); Clamp keeps them
// as candidates with the clamped features; Extrapolate keeps them as
// candidates with the trajectory continued at the constant speed and turning
// rate of the clip's last kExtrapolateSeconds (before the first frame: of
// its first), and excludes only the clip's last kExtrapolateEndSeconds and
// frames whose phase window crosses an edge.
// Looping clips always wrap. Extrapolate suits short takes of steady
// locomotion, whose last second Exclude would drop: a take that ends in
// mid-stride did not stop there.
enum class EdgeRule : std::uint8_t { Exclude, Clamp, Extrapolate };

// The stretch of a clip whose motion Extrapolate continues: the most recent
// speed and turning rate predict best. Measured on CMU takes cut short
// (tests/data/trajectory_extrapolation_test.cpp, 1,980 frames), the mean
// error of the 1 s trajectory was 0.376 m clamped; extrapolated over one
// frame 0.155 m, over 0.1 s 0.165 m, 0.25 s 0.192 m, 1 s 0.314 m. 0.1 s
// rather than one frame, so that a 120 fps clip does not extrapolate one
// noisy 8 ms step.
inline constexpr float kExtrapolateSeconds = 0.1f;

// Extrapolate still excludes a clip's last this many seconds (at least one
// frame): a frame there would play into the clip's end within a few ticks,
// and the end can only be left by another jump. On the CMU subject 16 set
// (1,000 characters, 20 s) 0.1 s forced 21,414 searches, 0.2 s 4,762,
// 0.33 s 4,755; 0.5 s left too few frames of the 1.1 s run to count as one.
inline constexpr float kExtrapolateEndSeconds = 0.2f;

// "exclude", "clamp", "extrapolate".
std::string_view edge_rule_name(EdgeRule rule);
// The rule named `name`; the error lists the names (the caller adds where).
Result<EdgeRule> parse_edge_rule(std::string_view name);

// A time range [begin, end) in seconds from the clip's start. A frame f of a
// clip at fps is inside when begin <= f / fps < end.
struct TimeRange {
  float begin_seconds = 0.0f;
  float end_seconds = 0.0f;
};

// A tag over a time range of a clip (manifest "tag_ranges").
struct TagRange {
  std::string tag;
  TimeRange range;
};

// A cost adjustment over a time range of a clip (manifest "cost_ranges").
struct CostRange {
  TimeRange range;
  float cost_multiplier = 1.0f;  // > 0, multiplies the clip's
  float cost_bias = 0.0f;        // finite, added to the clip's
};

struct ManifestClip {
  // The BVH, FBX, glTF or COLLADA file (resolved: absolute or relative to
  // the working directory).
  std::filesystem::path file;
  // For an FBX, glTF or COLLADA file: the one animation of this name;
  // empty = every animation, each its own clip named after it (the clip's
  // name when the file has one animation).
  std::string animation;
  // The part of the file the clip takes: frames f (at the build's rate) with
  // begin <= f / fps < end; none = the whole file. With `loop`, a cycle cut
  // out of a longer take; the clip's other time ranges count from its begin.
  std::optional<TimeRange> range;
  std::string name;                // unique per database is not required
  std::vector<std::string> tags;
  bool loop = false;
  bool mirror = false;             // also add a mirrored copy (a separate clip flagged mirrored)
  float cost_multiplier = 1.0f;    // > 0
  float cost_bias = 0.0f;          // finite
  std::vector<TimeRange> do_not_use;
  std::vector<TimeRange> block_transition;
  std::vector<TagRange> tag_ranges;    // in the manifest's order: per tag, its ranges
  std::vector<CostRange> cost_ranges;
  // The clip's place in the manifest for messages ("db.json: clips[2]");
  // empty for clips made in code.
  std::string field;
};

// How a sidecar channel's values mirror (manifest "mirror_map"): dim d of a
// mirrored frame is sign[d] * (dim source[d] of the source frame). "swap"
// pairs exchange two dims, "negate" flips the sign of a dim of the result.
// Sidecar channels without an entry are copied unchanged.
struct SidecarMirror {
  std::string channel;               // a custom channel of the schema
  std::vector<std::uint32_t> source; // [custom_dims]
  std::vector<float> sign;           // [custom_dims], +1 or -1
};

struct Manifest {
  std::string source;              // the manifest's path or the folder it was made from (for messages)
  FeatureSchema schema = default_schema();
  float fps = 0.0f;                // 0 = keep the source rate (all clips must share it)
  ImportOptions import;
  CharacterRootOptions character_root;
  EdgeRule edge_rule = EdgeRule::Exclude;
  std::vector<BonePair> mirror_bones;     // overrides mirror_pairs()' heuristics
  std::vector<SidecarMirror> mirror_map;
  FootContactParams contacts;      // the animation's contacts and the foot_contact channel
  GaitBandParams gait_bands;       // the measured gait tags (gait_bands.hpp)
  // The "crowd" object as JSON text, or empty: read by the crowd host
  // (host/crowd/setup/data_settings.hpp), which names its unknown keys; the build
  // only carries it into the database.
  std::string crowd;
  std::vector<ManifestClip> clips;
};

// Parses manifest JSON. `source` names it in messages; relative clip and
// schema paths are resolved against `base_dir`.
Result<Manifest> parse_manifest_json(std::string_view json_text, std::string_view source,
                                     const std::filesystem::path& base_dir);
Result<Manifest> load_manifest(const std::filesystem::path& path);

// Whether `path` names a BVH file by its extension (.bvh, any case).
bool is_bvh_path(const std::filesystem::path& path);

// Whether `path` names a motion file by its extension, as folders and build
// sources tell motion from manifests: BVH or a scene file (is_scene_path()).
bool is_motion_path(const std::filesystem::path& path);

// A manifest with defaults for every motion file (is_motion_path())
// directly in `dir`, sorted by file name; clip names are the file stems.
Result<Manifest> manifest_from_directory(const std::filesystem::path& dir);

// A manifest file, a folder of motion files or one motion file (one clip
// with the folder's defaults), whichever `path` is.
Result<Manifest> load_manifest_or_directory(const std::filesystem::path& path);

// Every file a build of `manifest` reads besides the manifest itself: each
// clip's BVH and its custom channels' sidecars (features.hpp), in clip order,
// for hosts that refuse an output that is one of them (manifest_files.cpp).
std::vector<std::filesystem::path> manifest_input_files(const Manifest& manifest);

}  // namespace mmvk
