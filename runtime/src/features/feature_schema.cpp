#include "mmvk/features/feature_schema.hpp"

#include <cmath>
#include <set>

#include "common/name_table.hpp"

namespace mmvk {

std::uint32_t FeatureChannel::dims() const {
  const ChannelKindInfo& info = channel_kind_info(kind);
  const auto labels = static_cast<std::uint32_t>(info.labels.size());
  switch (info.dims_rule) {
    case DimsRule::Labels:
      return labels;
    case DimsRule::LabelsPerOffset:
      return labels * static_cast<std::uint32_t>(offsets_seconds.size());
    case DimsRule::Declared:
      return custom_dims;
    case DimsRule::LabelsPerCurve:
      return labels * static_cast<std::uint32_t>(curves.size());
  }
  return 0;
}

std::uint32_t FeatureSchema::dims() const {
  std::uint32_t total = 0;
  for (const FeatureChannel& channel : channels) total += channel.dims();
  return total;
}

std::uint32_t FeatureSchema::offset(std::size_t channel) const {
  std::uint32_t total = 0;
  for (std::size_t c = 0; c < channel; ++c) total += channels[c].dims();
  return total;
}

int FeatureSchema::find(std::string_view name) const {
  for (std::size_t c = 0; c < channels.size(); ++c) {
    if (channels[c].name == name) return static_cast<int>(c);
  }
  return -1;
}

Result<std::size_t> FeatureSchema::find_channel(std::string_view name, std::string_view where) const {
  const int index = find(name);
  if (index >= 0) return static_cast<std::size_t>(index);
  return make_error(std::string(where) + ": unknown channel '" + std::string(name) + "' (the schema has: " +
                    channel_names() + ")");
}

std::string FeatureSchema::channel_names() const {
  std::string names;
  for (const FeatureChannel& channel : channels) {
    if (!names.empty()) names += ", ";
    names += channel.name;
  }
  return names;
}

std::string FeatureSchema::dim_name(std::uint32_t d) const {
  for (const FeatureChannel& channel : channels) {
    const std::uint32_t n = channel.dims();
    if (d < n) {
      const ChannelKindInfo& info = channel_kind_info(channel.kind);
      const std::size_t labels = info.labels.size();
      switch (info.dims_rule) {
        case DimsRule::Labels:
          return channel.name + "." + std::string(info.labels[d]);
        case DimsRule::LabelsPerOffset:
        case DimsRule::LabelsPerCurve:
          return channel.name + "[" + std::to_string(d / labels) + "]." + std::string(info.labels[d % labels]);
        case DimsRule::Declared:
          return channel.name + "[" + std::to_string(d) + "]";
      }
    }
    d -= n;
  }
  return "dim " + std::to_string(d) + " (beyond the schema)";
}

Status FeatureSchema::validate() const {
  if (channels.empty()) return make_error("schema: no channels");
  if (channels.size() > kMaxChannels) {
    return make_error("schema: " + std::to_string(channels.size()) + " channels, at most " +
                      std::to_string(kMaxChannels) + " are supported");
  }
  std::set<std::string> names;
  for (std::size_t c = 0; c < channels.size(); ++c) {
    const FeatureChannel& channel = channels[c];
    const std::string where = "schema: channel " + std::to_string(c) + " ('" + channel.name + "')";
    if (channel.name.empty()) return make_error("schema: channel " + std::to_string(c) + " has no name");
    if (!names.insert(channel.name).second) return make_error(where + ": duplicate name");
    if (!(channel.weight > 0.0f) || !std::isfinite(channel.weight)) {
      return make_error(where + ": weight must be finite and > 0");
    }
    const ChannelKindInfo& info = channel_kind_info(channel.kind);
    if (has_field(info.fields, ChannelField::Offsets)) {
      if (channel.offsets_seconds.empty()) return make_error(where + ": offsets_seconds is empty");
      for (float t : channel.offsets_seconds) {
        // Negative offsets are the past trajectory; 0 is the current frame,
        // which is the origin of character space and carries nothing.
        if (t == 0.0f || !std::isfinite(t)) return make_error(where + ": offsets_seconds must be finite and != 0");
      }
    }
    if (has_field(info.fields, ChannelField::Curves)) {
      if (channel.curves.empty()) return make_error(where + ": curves is empty");
      if (!(channel.window_seconds > 0.0f) || !std::isfinite(channel.window_seconds)) {
        return make_error(where + ": window_seconds must be finite and > 0");
      }
    }
    if (has_field(info.fields, ChannelField::Bone) && info.default_bone.empty() && channel.bone.empty()) {
      return make_error(where + ": bone is missing");
    }
    if (has_field(info.fields, ChannelField::SecondBone) && channel.second_bone.empty()) {
      return make_error(where + ": second_bone is missing");
    }
    if (has_field(info.fields, ChannelField::Dims) && channel.custom_dims == 0) {
      return make_error(where + ": dims must be > 0");
    }
  }
  return {};
}

namespace {

constexpr NamedLimb kLimbs[] = {
    {"left_leg", "@hips", "@left_foot"},
    {"right_leg", "@hips", "@right_foot"},
    {"left_arm", "@left_shoulder", "@left_hand"},
    {"right_arm", "@right_shoulder", "@right_hand"},
};

}  // namespace

std::span<const NamedLimb> named_limbs() { return kLimbs; }

const NamedLimb* find_limb(std::string_view name) { return detail::find_named(named_limbs(), &NamedLimb::name, name); }

std::string limb_list() { return detail::name_list(named_limbs(), &NamedLimb::name, '"', true); }

FeatureSchema default_schema() {
  const std::vector<float> offsets = {1.0f / 3.0f, 2.0f / 3.0f, 1.0f};
  auto bone_channel = [](std::string name, ChannelKind kind, std::string bone) {
    FeatureChannel channel;
    channel.name = std::move(name);
    channel.kind = kind;
    channel.bone = std::move(bone);
    return channel;
  };
  auto trajectory_channel = [&](std::string name, ChannelKind kind) {
    FeatureChannel channel;
    channel.name = std::move(name);
    channel.kind = kind;
    channel.offsets_seconds = offsets;
    return channel;
  };
  FeatureSchema schema;
  schema.channels = {
      bone_channel("left_foot_position", ChannelKind::BonePosition, "@left_foot"),
      bone_channel("right_foot_position", ChannelKind::BonePosition, "@right_foot"),
      bone_channel("left_foot_velocity", ChannelKind::BoneVelocity, "@left_foot"),
      bone_channel("right_foot_velocity", ChannelKind::BoneVelocity, "@right_foot"),
      bone_channel("hip_velocity", ChannelKind::RootVelocity, "@hips"),
      trajectory_channel("trajectory_position", ChannelKind::TrajectoryPosition),
      trajectory_channel("trajectory_direction", ChannelKind::TrajectoryDirection),
  };
  return schema;
}

}  // namespace mmvk
