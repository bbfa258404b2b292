// The table of channel kinds: each kind of feature channel is one entry,
// holding everything the schema, its JSON form, feature extraction, the CLI
// and the benchmarks need to know about it. Nothing else switches over
// ChannelKind, so adding a kind is one enum value, one entry in
// runtime/src/features/channel_kinds.cpp and one extractor function (see
// runtime/README.md, "Adding a channel kind").
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace mmvk {

enum class ChannelKind : std::uint8_t {
  TrajectoryPosition,   // past/future root positions (x, z) in character space, metres; 2 dims per offset
  TrajectoryDirection,  // past/future facing directions (x, z) in character space; 2 dims per offset
  BonePosition,         // bone position (x, y, z) in character space, metres; 3 dims
  BoneVelocity,         // bone velocity (x, y, z) in character space, m/s; 3 dims
  RootVelocity,         // hip (source bone) velocity (x, y, z) in character space, m/s; 3 dims
  Custom,               // per-frame values from a sidecar file; `custom_dims` dims
  RootAngularVelocity,  // the root's turning rate about +Y, rad/s, positive = turning left; 1 dim
  FootContact,          // 0/1 per foot (left, right) from the animation's contact detection; 2 dims
  LimbVector,           // (limb end - limb root) / limb length in character space, unitless; 3 dims
  Phase,                // per source curve (a sin 2 pi phi, a cos 2 pi phi) of its dominant frequency; 2 dims per curve
};

// The FeatureChannel fields a kind reads (a bit set). A field a kind reads is
// required, except `bone` when the kind names a default bone.
enum class ChannelField : std::uint8_t {
  None = 0,
  Bone = 1,        // FeatureChannel::bone, a joint name or role
  SecondBone = 2,  // FeatureChannel::second_bone (for kinds spanning two joints)
  Offsets = 4,     // FeatureChannel::offsets_seconds: the kind samples the root trajectory at these times
  Dims = 8,        // FeatureChannel::custom_dims: the values come from a sidecar, this many per frame
  Curves = 16,     // FeatureChannel::curves and window_seconds: the kind reads source curves over a window
  Contacts = 32,   // no field: the kind reads the clip's foot contacts (FeatureExtractionOptions::contacts)
};
constexpr ChannelField operator|(ChannelField a, ChannelField b) {
  return static_cast<ChannelField>(static_cast<std::uint8_t>(a) | static_cast<std::uint8_t>(b));
}
constexpr bool has_field(ChannelField set, ChannelField field) {
  return (static_cast<std::uint8_t>(set) & static_cast<std::uint8_t>(field)) != 0;
}

// How a channel's dims follow from its fields.
enum class DimsRule : std::uint8_t {
  Labels,           // one dim per label: "name.x"
  LabelsPerOffset,  // the labels once per trajectory offset: "name[i].x"
  Declared,         // `custom_dims` dims, named by index: "name[i]"
  LabelsPerCurve,   // the labels once per source curve: "name[i].sin"
};

// What a mirrored clip (manifest "mirror") does to the kind's values.
enum class MirrorRule : std::uint8_t {
  Remeasured,  // extracted again from the mirrored motion (roles then name the mirrored joints)
  Unchanged,   // copied from the source clip (sidecar values), through the manifest's mirror_map when it has an entry
};

// Where a crowd controller's query takes the kind's values from, measured on
// what the character shows (query_assembly.hpp).
enum class ShownSource : std::uint8_t {
  Trajectory,     // future offsets from the predicted trajectory, past offsets from the root's recorded path
  JointPosition,  // the bone's position in the displayed pose
  JointVelocity,  // the bone's velocity in the displayed motion
  Limb,           // the limb vector of the displayed pose
  YawRate,        // the root's turning rate
  Contacts,       // the displayed frame's foot contacts
  Row,            // not measurable on a pose: the nearest database frame's values
};

namespace detail {
struct ChannelExtraction;  // runtime/src/features/channel_extraction.hpp
}  // namespace detail

// Fills one channel's dims for every frame of a clip.
using ChannelExtractor = void (*)(const detail::ChannelExtraction& job);

// The largest |value| a real capture can give a kind measured in metres (in
// character space) or metres per second: far beyond any human motion
// (sprinting is ~10 m/s, a hand's swing ~30 m/s) and its capture noise. A
// database build rejects a clip beyond them (database_build.hpp), since one
// corrupt value would set its channel's normalization scale.
inline constexpr float kMaxPlausiblePosition = 1000.0f;  // metres
inline constexpr float kMaxPlausibleSpeed = 1000.0f;     // metres per second

struct ChannelKindInfo {
  ChannelKind kind;
  std::string_view name;          // the JSON name, e.g. "trajectory_position"
  std::string_view summary;       // one line: what the values are, in which units
  DimsRule dims_rule;
  std::span<const std::string_view> labels;  // dimension labels (empty for DimsRule::Declared)
  ChannelField fields;            // the FeatureChannel fields the kind reads
  std::string_view default_bone;  // used when `bone` is empty; empty = `bone` is required
  MirrorRule mirror;
  float plausible_limit = 0.0f;   // largest plausible |value| (above), 0 = unchecked
  std::string_view limit_unit;    // the limit's unit for messages: "m", "m/s"
  ShownSource shown;              // what a controller's query measures it on
  ChannelExtractor extract;       // library-internal
};

// Every kind, in ChannelKind order.
std::span<const ChannelKindInfo> channel_kinds();
const ChannelKindInfo& channel_kind_info(ChannelKind kind);
// The kind with JSON name `name`, or nullptr.
const ChannelKindInfo* find_channel_kind(std::string_view name);
// The JSON names, quoted and comma-separated, for error messages.
std::string channel_kind_list();

// The kind samples the root trajectory at its offsets_seconds, and a query's
// "trajectory" part (as opposed to its pose) is made of such channels.
inline bool uses_trajectory_offsets(ChannelKind kind) {
  return has_field(channel_kind_info(kind).fields, ChannelField::Offsets);
}

// The kind reads frames around the current one (trajectory offsets, a phase
// window): its frames near a non-looping clip's start or end fall under the
// edge rule (features.hpp: edge_reach()).
inline bool follows_edge_rule(ChannelKind kind) {
  const ChannelField fields = channel_kind_info(kind).fields;
  return has_field(fields, ChannelField::Offsets) || has_field(fields, ChannelField::Curves);
}

// The kind's values come from the caller (a sidecar file beside each clip,
// see features.hpp), custom_dims per frame.
inline bool reads_sidecar(ChannelKind kind) { return has_field(channel_kind_info(kind).fields, ChannelField::Dims); }

}  // namespace mmvk
