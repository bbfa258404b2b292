// The database manifest: which BVH clips go into a database, with their tags,
// flags and cost adjustments, and the database-level build options.
//
// JSON form (every field but "clips" optional; unknown fields are errors):
// {
//   "schema": "schema.json" | { "channels": [...] },   // default: default_schema()
//   "fps": 30,                 // resample every clip to this rate; default: keep the source rate
//   "import": { "metres_per_unit": 0.01, "up_axis": "y" | "z" },
//   "character_root": { "source_bone": "@hips", "facing_smoothing_seconds": 0.5 },
//   "edge_rule": "exclude" | "clamp",                    // default "exclude"
//   "mirror": false,           // add a mirrored copy of every clip
//   "clips": [
//     { "file": "walk.bvh",    // relative paths are relative to the manifest's folder
//       "name": "walk",        // default: the file name without extension
//       "tags": ["walk"], "loop": false, "mirror": false,
//       "cost_multiplier": 1.0, "cost_bias": 0.0,
//       "do_not_use": [[0.0, 0.5]],         // [begin, end) in seconds
//       "block_transition": [[2.0, 2.5]] }
//   ]
// }
// Error messages name the manifest and the field: "db.json: clips[2].loop:
// expected true or false".
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/character.hpp"
#include "mmvk/feature_schema.hpp"
#include "mmvk/motion.hpp"
#include "mmvk/status.hpp"

namespace mmvk {

// What happens to frames whose furthest trajectory offset runs past the end of
// a non-looping clip: Exclude flags them kFrameEdgeExcluded (they are never
// search results; their features clamp to the last frame); Clamp keeps them
// as candidates with the clamped features. Looping clips always wrap.
enum class EdgeRule : std::uint8_t { Exclude, Clamp };

// A time range [begin, end) in seconds from the clip's start. A frame f of a
// clip at fps is inside when begin <= f / fps < end.
struct TimeRange {
  float begin_seconds = 0.0f;
  float end_seconds = 0.0f;
};

struct ManifestClip {
  std::filesystem::path file;      // the BVH file (resolved: absolute or relative to the working directory)
  std::string name;                // unique per database is not required
  std::vector<std::string> tags;
  bool loop = false;
  bool mirror = false;             // also add a mirrored copy (a separate clip flagged mirrored)
  float cost_multiplier = 1.0f;    // > 0
  float cost_bias = 0.0f;          // finite
  std::vector<TimeRange> do_not_use;
  std::vector<TimeRange> block_transition;
};

struct Manifest {
  std::string source;              // the manifest's path or the folder it was made from (for messages)
  FeatureSchema schema = default_schema();
  float fps = 0.0f;                // 0 = keep the source rate (all clips must share it)
  ImportOptions import;
  CharacterRootOptions character_root;
  EdgeRule edge_rule = EdgeRule::Exclude;
  std::vector<ManifestClip> clips;
};

// Parses manifest JSON. `source` names it in messages; relative clip and
// schema paths are resolved against `base_dir`.
Result<Manifest> parse_manifest_json(std::string_view json_text, std::string_view source,
                                     const std::filesystem::path& base_dir);
Result<Manifest> load_manifest(const std::filesystem::path& path);

// A manifest with defaults for every *.bvh (case-insensitive extension)
// directly in `dir`, sorted by file name; clip names are the file stems.
Result<Manifest> manifest_from_directory(const std::filesystem::path& dir);

// A manifest file or a folder of BVH, whichever `path` is.
Result<Manifest> load_manifest_or_directory(const std::filesystem::path& path);

}  // namespace mmvk
