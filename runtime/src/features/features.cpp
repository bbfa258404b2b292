#include "mmvk/features/features.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "features/channel_extraction.hpp"
#include "features/foot_contacts.hpp"
#include "mmvk/common/file_io.hpp"

namespace mmvk {

namespace {

std::string where(const FeatureExtractionOptions& options, const FeatureChannel& channel) {
  return (options.source.empty() ? std::string("clip") : options.source) + ": channel '" + channel.name + "'";
}

// True when `joint` is `ancestor` or hangs below it.
bool hangs_below(const Skeleton& skeleton, int joint, int ancestor) {
  for (int j = joint; j >= 0; j = skeleton.parents[static_cast<std::size_t>(j)]) {
    if (j == ancestor) return true;
  }
  return false;
}

// A phase curve: the dimension name of an earlier channel, or
// "<bone>.speed" / "<bone>.height".
Result<detail::CurveSource> resolve_curve(const Skeleton& skeleton, const FeatureSchema& schema, std::size_t channel,
                                          const std::string& curve) {
  const std::uint32_t earlier = schema.offset(channel);
  for (std::uint32_t d = 0; d < earlier; ++d) {
    if (schema.dim_name(d) == curve) return detail::CurveSource{detail::CurveSource::Kind::Column, -1, d};
  }
  const std::size_t dot = curve.rfind('.');
  const std::string quantity = dot == std::string::npos ? std::string() : curve.substr(dot + 1);
  if (quantity != "speed" && quantity != "height") {
    return make_error("\"" + curve + "\" is neither \"<bone>.speed\", \"<bone>.height\" nor the name of a " +
                      "dimension of an earlier channel (e.g. \"" + (earlier > 0 ? schema.dim_name(0) : "...") + "\")");
  }
  Result<int> joint = find_bone(skeleton, curve.substr(0, dot));
  if (!joint.ok()) return make_error("\"" + curve + "\": " + joint.message());
  return detail::CurveSource{quantity == "speed" ? detail::CurveSource::Kind::Speed : detail::CurveSource::Kind::Height,
                             *joint, 0};
}

// "channel 'x': offsets_seconds[i] (-1.5 s)" for the schema's furthest past
// offset, empty when it has none.
std::string past_reach_owner(const FeatureSchema& schema, float fps) {
  std::string owner;
  std::uint32_t furthest = 0;
  for (const FeatureChannel& channel : schema.channels) {
    if (!uses_trajectory_offsets(channel.kind)) continue;
    for (std::size_t i = 0; i < channel.offsets_seconds.size(); ++i) {
      const float t = channel.offsets_seconds[i];
      if (t < 0.0f && offset_frames(-t, fps) > furthest) {
        furthest = offset_frames(-t, fps);
        owner = "channel '" + channel.name + "': offsets_seconds[" + std::to_string(i) + "] (" + std::to_string(t) +
                " s)";
      }
    }
  }
  return owner;
}

}  // namespace

std::uint32_t offset_frames(float offset_seconds, float fps) {
  const double frames = std::round(static_cast<double>(offset_seconds) * static_cast<double>(fps));
  if (!(frames >= 1.0)) return 1;
  if (frames > 1e9) return 1000000000u;
  return static_cast<std::uint32_t>(frames);
}

std::int64_t signed_offset_frames(float offset_seconds, float fps) {
  const std::int64_t frames = offset_frames(std::abs(offset_seconds), fps);
  return offset_seconds < 0.0f ? -frames : frames;
}

std::uint32_t window_frames(float window_seconds, float fps) { return offset_frames(window_seconds, fps); }

std::uint32_t max_offset_frames(const FeatureSchema& schema, float fps) {
  std::uint32_t result = 0;
  for (const FeatureChannel& channel : schema.channels) {
    if (!uses_trajectory_offsets(channel.kind)) continue;
    for (float t : channel.offsets_seconds) {
      if (t > 0.0f) result = std::max(result, offset_frames(t, fps));
    }
  }
  return result;
}

EdgeReach edge_reach(const FeatureSchema& schema, float fps, bool trajectory) {
  EdgeReach reach;
  for (const FeatureChannel& channel : schema.channels) {
    const ChannelField fields = channel_kind_info(channel.kind).fields;
    if (trajectory && has_field(fields, ChannelField::Offsets)) {
      for (float t : channel.offsets_seconds) {
        std::uint32_t& side = t < 0.0f ? reach.before : reach.after;
        side = std::max(side, offset_frames(std::abs(t), fps));
      }
    }
    if (has_field(fields, ChannelField::Curves)) {
      const std::uint32_t half = window_frames(channel.window_seconds, fps);
      reach.before = std::max(reach.before, half);
      reach.after = std::max(reach.after, half);
    }
  }
  return reach;
}

namespace {

// A channel's inputs, resolved once per clip (skeletons may differ between clips).
struct ChannelInputs {
  int bone = -1;
  int second_bone = -1;
  std::span<const float> custom;
  std::vector<detail::CurveSource> curves;
};

// Channel c's bones, curves and custom values; `custom_count` counts the
// custom channels so far (the next one takes options.custom[custom_count]).
Status resolve_channel(const Motion& motion, const FeatureSchema& schema, std::size_t c,
                       const FeatureExtractionOptions& options, std::size_t& custom_count, ChannelInputs& inputs) {
  const FeatureChannel& channel = schema.channels[c];
  const ChannelKindInfo& info = channel_kind_info(channel.kind);
  const std::uint32_t frames = motion.frame_count;
  if (has_field(info.fields, ChannelField::Bone)) {
    const std::string bone = channel.bone.empty() ? std::string(info.default_bone) : channel.bone;
    Result<int> index = find_bone(motion.skeleton, bone);
    if (!index.ok()) return make_error(where(options, channel) + ": " + index.message());
    inputs.bone = *index;
  }
  if (has_field(info.fields, ChannelField::SecondBone)) {
    Result<int> index = find_bone(motion.skeleton, channel.second_bone);
    if (!index.ok()) return make_error(where(options, channel) + ": second_bone: " + index.message());
    inputs.second_bone = *index;
    if (has_field(info.fields, ChannelField::Bone) && !hangs_below(motion.skeleton, *index, inputs.bone)) {
      return make_error(where(options, channel) + ": second_bone '" + channel.second_bone + "' (" +
                        motion.skeleton.names[static_cast<std::size_t>(*index)] + ") does not hang below bone '" +
                        channel.bone + "' (" + motion.skeleton.names[static_cast<std::size_t>(inputs.bone)] + ")");
    }
  }
  if (has_field(info.fields, ChannelField::Curves)) {
    const std::uint32_t half = window_frames(channel.window_seconds, motion.fps);
    if (std::uint64_t{2} * half + 1 > frames) {
      return make_error(where(options, channel) + ": window_seconds " + std::to_string(channel.window_seconds) +
                        " spans " + std::to_string(2 * half + 1) + " frames, longer than the clip (" +
                        std::to_string(frames) + " frames)");
    }
    for (std::size_t i = 0; i < channel.curves.size(); ++i) {
      Result<detail::CurveSource> curve = resolve_curve(motion.skeleton, schema, c, channel.curves[i]);
      if (!curve.ok()) {
        return make_error(where(options, channel) + ": curves[" + std::to_string(i) + "]: " + curve.message());
      }
      inputs.curves.push_back(*curve);
    }
  }
  if (has_field(info.fields, ChannelField::Dims)) {
    if (custom_count < options.custom.size()) {
      const std::vector<float>& values = options.custom[custom_count];
      if (values.size() != std::size_t{frames} * channel.custom_dims) {
        return make_error(where(options, channel) + ": custom values hold " + std::to_string(values.size()) +
                          " floats, expected " + std::to_string(frames) + " frames x " +
                          std::to_string(channel.custom_dims) + " dims");
      }
      inputs.custom = values;
    }
    ++custom_count;
  }
  return {};
}

// Every channel's inputs, and whether any channel reads foot contacts.
Status resolve_inputs(const Motion& motion, const FeatureSchema& schema, const FeatureExtractionOptions& options,
                      const std::string& source, std::vector<ChannelInputs>& inputs, bool& needs_contacts) {
  inputs.resize(schema.channels.size());
  std::size_t custom_count = 0;
  needs_contacts = false;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    MMVK_TRY(resolve_channel(motion, schema, c, options, custom_count, inputs[c]));
    if (has_field(channel_kind_info(schema.channels[c].kind).fields, ChannelField::Contacts)) needs_contacts = true;
  }
  if (custom_count != options.custom.size()) {
    return make_error(source + ": the schema has " + std::to_string(custom_count) + " custom channels, " +
                      std::to_string(options.custom.size()) + " custom arrays were given");
  }
  return {};
}

// Global positions of every joint, [frames x joints], shared by the channels.
void sample_global_positions(const Motion& motion, std::vector<glm::vec3>& global) {
  const std::size_t joints = motion.joint_count();
  std::vector<glm::vec3> positions(joints);
  std::vector<glm::quat> rotations(joints);
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    forward_kinematics(motion, f, positions, rotations);
    std::copy(positions.begin(), positions.end(), global.begin() + static_cast<std::ptrdiff_t>(std::size_t{f} * joints));
  }
}

Status detect_contacts(detail::ClipSamples& clip, const FeatureExtractionOptions& options, const std::string& source) {
  const Motion& motion = clip.motion;
  detail::ClipContacts contacts =
      detail::detect_foot_contacts(motion.skeleton, clip.global, motion.frame_count, motion.fps, options.contacts);
  if (!contacts.resolved()) {
    return make_error(source + ": foot contacts: neither the toes ('" + options.contacts.left_toe + "', '" +
                      options.contacts.right_toe + "') nor the heels ('" + options.contacts.left_heel + "', '" +
                      options.contacts.right_heel + "') of both feet resolve on the clip's skeleton");
  }
  clip.contacts = std::move(contacts.bits);
  return {};
}

// Marks the frames whose past or future offsets reach over a non-looping
// clip's edges; refuses a clip where that is every frame.
Status mark_past_end(const FeatureSchema& schema, const Motion& motion, const FeatureExtractionOptions& options,
                     bool extrapolate, const std::string& source, RawFeatures& out) {
  const std::uint32_t frames = motion.frame_count;
  const EdgeReach reach = edge_reach(schema, motion.fps, !extrapolate);
  // Extrapolated past offsets leave every frame usable: no reach to check.
  const std::string past_owner = extrapolate ? std::string() : past_reach_owner(schema, motion.fps);
  if (!options.loop && !past_owner.empty() && std::uint64_t{reach.before} + reach.after >= frames) {
    return make_error(source + ": " + past_owner + " reaches " +
                      std::to_string(reach.before) + " frames back and the schema " + std::to_string(reach.after) +
                      " ahead: no frame of the " + std::to_string(frames) +
                      "-frame non-looping clip lies inside both edges");
  }
  for (std::uint32_t f = 0; f < frames; ++f) {
    if (!options.loop && (f < reach.before || std::uint64_t{f} + reach.after > std::uint64_t{frames} - 1)) {
      out.past_end[f] = 1;
    }
  }
  return {};
}

Status check_finite(const RawFeatures& out, const FeatureSchema& schema, const std::string& source) {
  for (std::size_t i = 0; i < out.values.size(); ++i) {
    if (!std::isfinite(out.values[i])) {
      return make_error(source + ": feature " + schema.dim_name(static_cast<std::uint32_t>(i % out.dims)) +
                        " of frame " + std::to_string(i / out.dims) + " is not finite");
    }
  }
  return {};
}

}  // namespace

Result<RawFeatures> extract_features(const Motion& motion, const CharacterRoot& root, const FeatureSchema& schema,
                                     const FeatureExtractionOptions& options) {
  MMVK_TRY(schema.validate());
  const std::uint32_t frames = motion.frame_count;
  const std::uint32_t dims = schema.dims();
  const std::string source = options.source.empty() ? std::string("clip") : options.source;
  if (!(motion.fps > 0.0f) || !std::isfinite(motion.fps)) {
    return make_error(source + ": frame rate must be positive, got " + std::to_string(motion.fps));
  }
  if (root.positions.size() != frames || root.facings.size() != frames) {
    return make_error(source + ": character root has " + std::to_string(root.positions.size()) +
                      " frames, the motion has " + std::to_string(frames));
  }
  std::vector<ChannelInputs> inputs;
  bool needs_contacts = false;
  MMVK_TRY(resolve_inputs(motion, schema, options, source, inputs, needs_contacts));

  const bool extrapolate = options.extrapolate_seconds > 0.0f && !options.loop;
  const std::uint32_t extrapolate_frames = extrapolate ? window_frames(options.extrapolate_seconds, motion.fps) : 0;
  detail::ClipSamples clip{motion, root, detail::Trajectory(root, frames, options.loop, extrapolate_frames),
                           std::vector<glm::vec3>(std::size_t{frames} * motion.joint_count()), options.loop, {}};
  sample_global_positions(motion, clip.global);
  if (needs_contacts) MMVK_TRY(detect_contacts(clip, options, source));

  RawFeatures out;
  out.frame_count = frames;
  out.dims = dims;
  out.values.assign(std::size_t{frames} * dims, 0.0f);
  out.past_end.assign(frames, 0);
  MMVK_TRY(mark_past_end(schema, motion, options, extrapolate, source, out));
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const detail::ChannelExtraction job{.clip = clip,
                                        .channel = schema.channels[c],
                                        .bone = inputs[c].bone,
                                        .second_bone = inputs[c].second_bone,
                                        .custom = inputs[c].custom,
                                        .curves = inputs[c].curves,
                                        .features = out.values.data(),
                                        .out = out.values.data() + schema.offset(c),
                                        .stride = dims};
    channel_kind_info(schema.channels[c].kind).extract(job);
  }
  MMVK_TRY(check_finite(out, schema, source));
  return out;
}

std::filesystem::path custom_sidecar_path(const std::filesystem::path& bvh_path, const FeatureChannel& channel) {
  std::filesystem::path path = bvh_path;
  path.replace_extension();
  path += "." + channel.name + ".f32";
  return path;
}

Result<std::vector<float>> load_custom_sidecar(const std::filesystem::path& bvh_path, const FeatureChannel& channel,
                                               std::uint32_t frame_count) {
  const std::filesystem::path path = custom_sidecar_path(bvh_path, channel);
  Result<std::vector<float>> values = read_f32_rows(path, channel.custom_dims, frame_count);
  if (!values.ok()) {
    return make_error(values.message() + " (custom channel '" + channel.name + "' of " + bvh_path.string() + ")");
  }
  for (std::size_t i = 0; i < values->size(); ++i) {
    if (!std::isfinite((*values)[i])) {
      return make_error(path.string() + ": value " + std::to_string(i % channel.custom_dims) + " of frame " +
                        std::to_string(i / channel.custom_dims) + " is not finite");
    }
  }
  return values;
}

std::vector<float> resample_values(std::span<const float> values, std::uint32_t dims, std::uint32_t src_frames,
                                   float src_fps, std::uint32_t dst_frames, float dst_fps) {
  std::vector<float> out(std::size_t{dst_frames} * dims, 0.0f);
  if (src_frames == 0 || dims == 0) return out;
  for (std::uint32_t f = 0; f < dst_frames; ++f) {
    const double t = std::min(static_cast<double>(f) / dst_fps * src_fps, static_cast<double>(src_frames - 1));
    const std::uint32_t a = static_cast<std::uint32_t>(t);
    const std::uint32_t b = std::min(a + 1, src_frames - 1);
    const float w = static_cast<float>(t - a);
    for (std::uint32_t d = 0; d < dims; ++d) {
      const float va = values[std::size_t{a} * dims + d];
      const float vb = values[std::size_t{b} * dims + d];
      out[std::size_t{f} * dims + d] = va + (vb - va) * w;
    }
  }
  return out;
}

}  // namespace mmvk
