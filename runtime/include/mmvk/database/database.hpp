// The motion database: the normalized feature matrix, the normalization that
// produced it, clips and per-frame metadata. Immutable once created; every
// search backend (CPU and Vulkan) reads it, none modifies it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/database/gait_bands.hpp"
#include "mmvk/features/normalization.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

using TagMask = std::uint64_t;  // bit t set = the frame carries tag_names()[t]
inline constexpr std::size_t kMaxTags = 64;

// Per-frame flags.
enum FrameFlag : std::uint32_t {
  kFrameDoNotUse = 1u << 0,         // never a result
  kFrameBlockTransition = 1u << 1,  // may be continued into, never jumped into
  kFrameEdgeExcluded = 1u << 2,     // future trajectory runs past a non-looping clip's end
};

struct Clip {
  std::string name;
  std::string source;               // the BVH file it came from
  TagMask tags = 0;
  bool loop = false;
  bool mirrored = false;
  float cost_multiplier = 1.0f;     // > 0
  float cost_bias = 0.0f;           // added to every frame's cost
  std::uint32_t first_frame = 0;    // database frame index of the clip's first frame
  std::uint32_t frame_count = 0;
  // Metres per unit of the source file, as the import used them (given by
  // the manifest or guessed); 0 = not recorded (clips made in code, files
  // before format 4).
  float metres_per_unit = 0.0f;
  // Where the import took the units and the up axis from ("the manifest's
  // import.metres_per_unit", "guessed from the skeleton's size", "FBX
  // UnitScaleFactor 1", ...); empty = not recorded (before format 7).
  std::string units_from;
  std::string axes_from;
};

// Everything a Database is made of; Database::create validates it.
struct DatabaseParts {
  FeatureSchema schema;
  float fps = 0.0f;
  std::vector<DimNormalization> normalization;  // [dims]
  std::vector<std::string> tag_names;           // <= kMaxTags, unique
  std::vector<Clip> clips;                      // contiguous, in frame order, covering all frames
  std::vector<std::uint32_t> frame_flags;       // [frames], FrameFlag bits
  std::vector<float> features;                  // [frames x dims], normalized, row-major
  // Per-frame tags and cost modifiers, each [frames] or empty. Empty means
  // every frame takes its clip's value; set, they are the frames' complete
  // values (a manifest's tag_ranges and cost_ranges: the clip's tags OR the
  // ranges' tags, the clip's multiplier times the ranges' multipliers, the
  // clip's bias plus the ranges' biases; database_build.hpp).
  std::vector<TagMask> frame_tags;
  std::vector<float> frame_multiplier;          // each finite and > 0
  std::vector<float> frame_bias;                // each finite
  // The skeleton and per-frame poses (animation_data.hpp); absent in a
  // database built with --no-animation or loaded from a format 1 file.
  std::optional<AnimationData> animation;
  // The manifest's "crowd" block as JSON text (a crowd host's tuned settings
  // for this data), or empty; not part of content_hash().
  std::string crowd_settings;
  // Why `animation` is absent, as the build saw it ("built with
  // --no-animation", or the clips whose skeletons differ); empty when it is
  // present or the file does not say (before format 7).
  std::string no_animation_reason;
  // The parameters the build measured the gait tags with (gait_bands.hpp),
  // or none (measurement off, a file before format 7). When set, the tag
  // names hold every kGaitTagNames entry.
  std::optional<GaitBandParams> gait_bands;
};

class Database {
 public:
  // Validates: schema, dims, finite features, positive scales, clip ranges,
  // tag masks within tag_names, multipliers > 0, finite biases (per clip and
  // per frame).
  static Result<Database> create(DatabaseParts parts);

  const FeatureSchema& schema() const { return parts_.schema; }
  float fps() const { return parts_.fps; }
  std::uint32_t frame_count() const { return frame_count_; }
  std::uint32_t dims() const { return dims_; }

  // Row-major [frame_count x dims], normalized.
  std::span<const float> features() const { return parts_.features; }
  std::span<const float> row(std::uint32_t frame) const { return {parts_.features.data() + std::size_t{frame} * dims_, dims_}; }
  std::span<const DimNormalization> normalization() const { return parts_.normalization; }
  std::span<const std::string> tag_names() const { return parts_.tag_names; }
  std::span<const Clip> clips() const { return parts_.clips; }
  // The animation section, or null when the database has none.
  const AnimationData* animation() const { return parts_.animation ? &*parts_.animation : nullptr; }
  // DatabaseParts::crowd_settings: JSON text of an object, or empty.
  const std::string& crowd_settings() const { return parts_.crowd_settings; }
  // DatabaseParts::no_animation_reason.
  const std::string& no_animation_reason() const { return parts_.no_animation_reason; }
  // DatabaseParts::gait_bands, or null when the frames carry no measured gait tags.
  const GaitBandParams* gait_bands() const { return parts_.gait_bands ? &*parts_.gait_bands : nullptr; }

  // Per-frame metadata, [frame_count] each (the clip's values repeated, or
  // DatabaseParts' per-frame values, so backends index them by frame without
  // a lookup).
  std::span<const std::uint32_t> frame_flags() const { return parts_.frame_flags; }
  std::span<const std::uint32_t> frame_clip() const { return frame_clip_; }
  std::span<const TagMask> frame_tags() const { return frame_tags_; }
  std::span<const float> frame_multiplier() const { return frame_multiplier_; }
  std::span<const float> frame_bias() const { return frame_bias_; }
  // [dims]: the largest |value| of each dimension over all rows, so a search
  // can bound a query's costs before computing them (validate_search).
  std::span<const float> max_abs_features() const { return max_abs_features_; }
  // The largest frame_multiplier() and |frame_bias()| (for the same bound).
  float max_multiplier() const { return max_multiplier_; }
  float max_abs_bias() const { return max_abs_bias_; }

  // Mask of the named tags; an unknown name is an error that names it.
  Result<TagMask> tag_mask(std::span<const std::string> names) const;
  // Normalizes a raw feature vector of dims() values (same offsets and scales
  // as the database rows). Precondition: raw.size() == out.size() == dims().
  void normalize(std::span<const float> raw, std::span<float> out) const;

  // A 64-bit digest of the search content (everything but the animation
  // section, so adding or dropping poses keeps cluster tables valid); cluster
  // tables and backends record it to detect being used with another database.
  std::uint64_t content_hash() const { return content_hash_; }

  const DatabaseParts& parts() const { return parts_; }

 private:
  explicit Database(DatabaseParts parts);

  DatabaseParts parts_;
  std::uint32_t frame_count_ = 0;
  std::uint32_t dims_ = 0;
  std::vector<std::uint32_t> frame_clip_;
  std::vector<TagMask> frame_tags_;
  std::vector<float> frame_multiplier_;
  std::vector<float> frame_bias_;
  std::vector<float> max_abs_features_;
  float max_multiplier_ = 0.0f;
  float max_abs_bias_ = 0.0f;
  std::uint64_t content_hash_ = 0;
};

}  // namespace mmvk
