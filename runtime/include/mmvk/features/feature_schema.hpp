// The feature schema: one table of channels that drives both the database
// build and the query build, so no layout offset is ever written by hand.
// Each channel is one normalization and weighting group.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

inline constexpr std::size_t kMaxChannels = 32;

enum class Normalization : std::uint8_t {
  GroupStd,     // z-score; one spread for the channel = mean of its per-dim std
  PerDimStd,    // z-score per dimension
  MeanAbsDev,   // mean absolute deviation per dimension (UE PoseSearch's choice)
  MinMax,       // (x - min) / (max - min) per dimension
};

struct FeatureChannel {
  std::string name;                     // unique within the schema
  ChannelKind kind = ChannelKind::BonePosition;
  std::string bone;                     // Bone*: joint name or role, see find_bone()
  std::string second_bone;              // kinds spanning two joints (LimbVector: the limb's end): joint name or role
  std::vector<float> offsets_seconds;   // Trajectory*: times from now, seconds, != 0 (< 0: the past)
  std::vector<std::string> curves;      // Phase: source curves, see features.hpp
  float window_seconds = 1.0f;          // Phase: half-width of the centred window, seconds, > 0
  std::uint32_t custom_dims = 0;        // Custom: dims per frame
  float weight = 1.0f;                  // > 0; folded into the scale (scale = spread / weight)
  Normalization normalization = Normalization::GroupStd;

  // By the kind's DimsRule (channel_kinds.hpp).
  std::uint32_t dims() const;
};

struct FeatureSchema {
  std::vector<FeatureChannel> channels;  // order = feature layout order

  std::uint32_t dims() const;
  // First feature dimension of channel `c`.
  std::uint32_t offset(std::size_t channel) const;
  // Index of the channel named `name`, or -1.
  int find(std::string_view name) const;
  // Index of the channel named `name`, or an error "<where>: unknown channel
  // '<name>' (the schema has: ...)".
  Result<std::size_t> find_channel(std::string_view name, std::string_view where) const;
  // The channel names, comma-separated, for messages.
  std::string channel_names() const;
  // Name of dimension d, e.g. "trajectory_position[1].z".
  std::string dim_name(std::uint32_t d) const;
  // Checks names, dims, weights, offsets and the channel count (<= kMaxChannels).
  Status validate() const;
};

// Named limbs for LimbVector channels ("limb": "left_leg" in JSON): the
// limb's root and end bones (roles, see find_bone()). Legs run from the hips
// to the ankles, arms from the shoulders (the upper arm joints) to the wrists.
struct NamedLimb {
  std::string_view name;  // "left_leg", "right_leg", "left_arm", "right_arm"
  std::string_view root;  // FeatureChannel::bone
  std::string_view end;   // FeatureChannel::second_bone
};
std::span<const NamedLimb> named_limbs();
const NamedLimb* find_limb(std::string_view name);  // nullptr when unknown
std::string limb_list();                              // quoted, comma-separated, for messages

// The names used in the JSON form ("trajectory_position", "group_std", ...).
std::string_view channel_kind_name(ChannelKind kind);
std::string_view normalization_name(Normalization mode);

// The widely used 27-d set: left/right foot positions and velocities, hip
// velocity, trajectory positions (x, z) and directions (x, z) at 0.33, 0.67
// and 1.0 s.
FeatureSchema default_schema();

// JSON form: {"channels": [{"name": ..., "kind": <a name from
// channel_kinds(): "trajectory_position", "bone_position", "custom", ...>,
// "bone": ..., "second_bone": ... (kinds that read it), "limb": a named limb
// (limb_vector, instead of bone and second_bone), "offsets_seconds": [...],
// "curves": [...], "window_seconds": s (phase), "dims": n, "weight": w,
// "normalization": "group_std" |
// "per_dim_std" | "mean_abs_dev" | "min_max"}]}. Errors name the field at
// fault.
Result<FeatureSchema> parse_schema_json(std::string_view json_text, std::string_view source);
Result<FeatureSchema> load_schema(const std::filesystem::path& path);
std::string schema_to_json(const FeatureSchema& schema);

}  // namespace mmvk
