// The table of channel kinds and the extractors of the built-in kinds. The
// rest of the library reads a kind's rules from here; a kind whose extractor
// grows large keeps it in a file of its own and names it in the table.
#include "mmvk/channel_kinds.hpp"

#include <algorithm>

#include "common/name_table.hpp"
#include "features/channel_extraction.hpp"
#include "mmvk/features.hpp"

namespace mmvk {

namespace {

using detail::ChannelExtraction;
using detail::GroundPose;
using detail::to_local;

constexpr std::string_view kXz[] = {"x", "z"};
constexpr std::string_view kXyz[] = {"x", "y", "z"};

// (x, z) of the root `offset` ahead, for every offset, in the current
// character space: a position relative to the root or a facing direction.
template <bool kPosition>
void extract_trajectory(const ChannelExtraction& job) {
  const detail::ClipSamples& clip = job.clip;
  for (std::uint32_t f = 0; f < clip.frames(); ++f) {
    const glm::vec3 origin = clip.root.positions[f];
    const glm::vec3 facing = clip.root.facings[f];
    float* row = job.row(f);
    for (float t : job.channel.offsets_seconds) {
      const GroundPose future = clip.trajectory.at(std::uint64_t{f} + offset_frames(t, clip.motion.fps));
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
     .extract = extract_custom},
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
