// The table of channel kinds and the extractors of the built-in kinds. The
// rest of the library reads a kind's rules from here; a kind whose extractor
// grows large keeps it in a file of its own and names it in the table.
#include "mmvk/features/channel_kinds.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "common/name_table.hpp"
#include "features/channel_extraction.hpp"
#include "mmvk/features/features.hpp"

namespace mmvk {

namespace {

using detail::ChannelExtraction;
using detail::GroundPose;
using detail::to_local;

constexpr std::string_view kXz[] = {"x", "z"};
constexpr std::string_view kXyz[] = {"x", "y", "z"};
constexpr std::string_view kYaw[] = {"yaw"};
constexpr std::string_view kFeet[] = {"left", "right"};
constexpr std::string_view kSinCos[] = {"sin", "cos"};

// (x, z) of the root `offset` ahead (or back, for a negative offset), for
// every offset, in the current character space: a position relative to the
// root or a facing direction.
template <bool kPosition>
void extract_trajectory(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    const glm::vec3 origin = clip.root.positions[f];
    const glm::vec3 facing = clip.root.facings[f];
    float* row = job.row(f);
    for (float t : job.channel.offsets_seconds) {
      const GroundPose future = clip.trajectory.at(std::int64_t{f} + signed_offset_frames(t, clip.motion.fps));
      const glm::vec3 local = kPosition ? to_local(future.position - origin, facing) : to_local(future.facing, facing);
      *row++ = local.x;
      *row++ = local.z;
    }
  }
}

void write_xyz(float* row, const glm::vec3& v) {
  row[0] = v.x;
  row[1] = v.y;
  row[2] = v.z;
}

void extract_bone_position(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    write_xyz(job.row(f), to_local(clip.bone_position(f, job.bone) - clip.root.positions[f], clip.root.facings[f]));
  }
}

void extract_bone_velocity(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    write_xyz(job.row(f), to_local(clip.bone_velocity(f, job.bone), clip.root.facings[f]));
  }
}

void extract_custom(const ChannelExtraction& job) {
  const std::uint32_t dims = job.channel.custom_dims;
  for (std::uint32_t f = 0; f < job.clip.frames(); ++f) {
    const float* src = job.custom.data() + std::size_t{f} * dims;
    std::copy(src, src + dims, job.row(f));
  }
}

// The signed angle from facing a to facing b about +Y (positive from +Z
// towards +X, i.e. turning left), radians.
float turn_angle(const glm::vec3& a, const glm::vec3& b) {
  return std::atan2(a.z * b.x - a.x * b.z, a.x * b.x + a.z * b.z);
}

// Finite differences of the facing angle, central inside the clip and
// one-sided at its ends, like bone velocities.
void extract_root_angular_velocity(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  const std::uint32_t n = clip.frames();
  for (std::uint32_t f = 0; f < n; ++f) {
    const std::uint32_t a = f > 0 ? f - 1 : f;
    const std::uint32_t b = f + 1 < n ? f + 1 : f;
    *job.row(f) = b > a ? turn_angle(clip.root.facings[a], clip.root.facings[b]) * clip.motion.fps / float(b - a)
                        : 0.0f;
  }
}

void extract_foot_contact(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    float* row = job.row(f);
    row[0] = (clip.contacts[f] & kContactLeft) != 0 ? 1.0f : 0.0f;
    row[1] = (clip.contacts[f] & kContactRight) != 0 ? 1.0f : 0.0f;
  }
}

// Divided by the limb's length on the same frame, so a character of another
// size (every offset scaled) gives the same values: the limb's direction and
// how far it is stretched.
void extract_limb_vector(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  const std::vector<int>& parents = clip.motion.skeleton.parents;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    float length = 0.0f;
    for (int j = job.second_bone; j != job.bone; j = parents[static_cast<std::size_t>(j)]) {
      length += glm::length(clip.bone_position(f, j) - clip.bone_position(f, parents[static_cast<std::size_t>(j)]));
    }
    const glm::vec3 limb = clip.bone_position(f, job.second_bone) - clip.bone_position(f, job.bone);
    // A zero-length chain (bone == second_bone) has no direction.
    const glm::vec3 value = length > 0.0f ? to_local(limb, clip.root.facings[f]) / length : glm::vec3(0.0f);
    write_xyz(job.row(f), value);
  }
}

// One entry per kind, in ChannelKind order.
constexpr ChannelKindInfo kKinds[] = {
    {.kind = ChannelKind::TrajectoryPosition,
     .name = "trajectory_position",
     .summary = "future root positions (x, z) in character space, metres",
     .dims_rule = DimsRule::LabelsPerOffset,
     .labels = kXz,
     .fields = ChannelField::Offsets,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,
     .plausible_limit = kMaxPlausiblePosition,
     .limit_unit = "m",
     .shown = ShownSource::Trajectory,
     .extract = extract_trajectory<true>},
    {.kind = ChannelKind::TrajectoryDirection,
     .name = "trajectory_direction",
     .summary = "future root facing directions (x, z) in character space, unit vectors",
     .dims_rule = DimsRule::LabelsPerOffset,
     .labels = kXz,
     .fields = ChannelField::Offsets,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,
     .plausible_limit = 0.0f,
     .limit_unit = {},
     .shown = ShownSource::Trajectory,
     .extract = extract_trajectory<false>},
    {.kind = ChannelKind::BonePosition,
     .name = "bone_position",
     .summary = "bone position (x, y, z) relative to the root, in character space, metres",
     .dims_rule = DimsRule::Labels,
     .labels = kXyz,
     .fields = ChannelField::Bone,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,
     .plausible_limit = kMaxPlausiblePosition,
     .limit_unit = "m",
     .shown = ShownSource::JointPosition,
     .extract = extract_bone_position},
    {.kind = ChannelKind::BoneVelocity,
     .name = "bone_velocity",
     .summary = "bone velocity (x, y, z) in character space, m/s",
     .dims_rule = DimsRule::Labels,
     .labels = kXyz,
     .fields = ChannelField::Bone,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,
     .plausible_limit = kMaxPlausibleSpeed,
     .limit_unit = "m/s",
     .shown = ShownSource::JointVelocity,
     .extract = extract_bone_velocity},
    {.kind = ChannelKind::RootVelocity,
     .name = "root_velocity",
     .summary = "hip (or `bone`) velocity (x, y, z) in character space, m/s",
     .dims_rule = DimsRule::Labels,
     .labels = kXyz,
     .fields = ChannelField::Bone,
     .default_bone = "@hips",
     .mirror = MirrorRule::Remeasured,
     .plausible_limit = kMaxPlausibleSpeed,
     .limit_unit = "m/s",
     .shown = ShownSource::JointVelocity,
     .extract = extract_bone_velocity},
    {.kind = ChannelKind::Custom,
     .name = "custom",
     .summary = "per-frame values from a sidecar file, `dims` per frame",
     .dims_rule = DimsRule::Declared,
     .labels = {},
     .fields = ChannelField::Dims,
     .default_bone = {},
     .mirror = MirrorRule::Unchanged,
     .plausible_limit = 0.0f,
     .limit_unit = {},
     .shown = ShownSource::Row,
     .extract = extract_custom},
    {.kind = ChannelKind::RootAngularVelocity,
     .name = "root_angular_velocity",
     .summary = "the root's turning rate about +Y, rad/s, positive = turning left",
     .dims_rule = DimsRule::Labels,
     .labels = kYaw,
     .fields = ChannelField::None,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,  // a mirrored clip turns the other way: the values negate
     .plausible_limit = 0.0f,  // bounded by pi x fps: a frame's turn is at most half a turn
     .limit_unit = {},
     .shown = ShownSource::YawRate,
     .extract = extract_root_angular_velocity},
    {.kind = ChannelKind::FootContact,
     .name = "foot_contact",
     .summary = "1 while the left / right foot is planted, else 0 (the animation's contact detection)",
     .dims_rule = DimsRule::Labels,
     .labels = kFeet,
     .fields = ChannelField::Contacts,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,  // measured on the mirrored skeleton: left and right swap
     .plausible_limit = 0.0f,
     .limit_unit = {},
     .shown = ShownSource::Contacts,
     .extract = extract_foot_contact},
    {.kind = ChannelKind::LimbVector,
     .name = "limb_vector",
     .summary = "(second_bone - bone) / limb length in character space, unitless",
     .dims_rule = DimsRule::Labels,
     .labels = kXyz,
     .fields = ChannelField::Bone | ChannelField::SecondBone,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,  // roles name the mirrored joints: left and right limbs swap
     .plausible_limit = 0.0f,
     .limit_unit = {},
     .shown = ShownSource::Limb,
     .extract = extract_limb_vector},
    {.kind = ChannelKind::Phase,
     .name = "phase",
     .summary = "per curve (a sin 2 pi phi, a cos 2 pi phi) of its dominant frequency over a centred window",
     .dims_rule = DimsRule::LabelsPerCurve,
     .labels = kSinCos,
     .fields = ChannelField::Curves,
     .default_bone = {},
     .mirror = MirrorRule::Remeasured,  // bone curves read the mirrored joints: left and right swap
     .plausible_limit = 0.0f,
     .limit_unit = {},
     .shown = ShownSource::Row,
     .extract = detail::extract_phase},
};

static_assert(detail::indexed_by(std::span<const ChannelKindInfo>(kKinds), &ChannelKindInfo::kind),
              "kKinds is indexed by ChannelKind");

}  // namespace

std::span<const ChannelKindInfo> channel_kinds() { return kKinds; }

const ChannelKindInfo& channel_kind_info(ChannelKind kind) { return detail::entry_for(channel_kinds(), kind); }

const ChannelKindInfo* find_channel_kind(std::string_view name) {
  return detail::find_named(channel_kinds(), &ChannelKindInfo::name, name);
}

std::string channel_kind_list() { return detail::name_list(channel_kinds(), &ChannelKindInfo::name, '"', true); }

std::string_view channel_kind_name(ChannelKind kind) {
  return detail::name_for(channel_kinds(), &ChannelKindInfo::name, kind);
}

}  // namespace mmvk
