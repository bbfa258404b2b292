#include "mmvk/features.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/file_io.hpp"

namespace mmvk {

namespace {

// A character root on the ground: position (y = 0) and unit facing in XZ.
struct GroundPose {
  glm::vec3 position{0.0f};
  glm::vec3 facing{0.0f, 0.0f, 1.0f};
};

// World vector -> character space of a root facing `facing` (+Z forward, +X left).
glm::vec3 to_local(const glm::vec3& v, const glm::vec3& facing) {
  return {v.x * facing.z - v.z * facing.x, v.y, v.x * facing.x + v.z * facing.z};
}

// Character space vector -> world (inverse of to_local).
glm::vec3 to_world(const glm::vec3& v, const glm::vec3& facing) {
  return {v.x * facing.z + v.z * facing.x, v.y, -v.x * facing.x + v.z * facing.z};
}

// `pose` expressed in the frame of `base`.
GroundPose relative(const GroundPose& base, const GroundPose& pose) {
  return {to_local(pose.position - base.position, base.facing), to_local(pose.facing, base.facing)};
}

// A pose given relative to `base`, back in world space.
GroundPose compose(const GroundPose& base, const GroundPose& rel) {
  return {base.position + to_world(rel.position, base.facing), to_world(rel.facing, base.facing)};
}

// Future root poses, looping or clamped. For a looping clip the frame after
// the last is the last advanced by the clip's final step; every further cycle
// repeats the rigid motion from frame 0 to that frame.
class Trajectory {
 public:
  Trajectory(const CharacterRoot& root, std::uint32_t frames, bool loop) : root_(root), frames_(frames), loop_(loop) {
    if (loop_ && frames_ > 0) {
      const GroundPose last = pose(frames_ - 1);
      const GroundPose step = frames_ >= 2 ? relative(pose(frames_ - 2), last) : GroundPose{};
      after_last_ = compose(last, step);
    }
  }

  // Root pose `j` frames from the start (j may run past the end).
  GroundPose at(std::uint64_t j) const {
    if (j < frames_) return pose(static_cast<std::uint32_t>(j));
    if (!loop_) return pose(frames_ - 1);
    GroundPose result = pose(static_cast<std::uint32_t>(j % frames_));
    const GroundPose first = pose(0);
    for (std::uint64_t cycle = j / frames_; cycle > 0; --cycle) result = compose(after_last_, relative(first, result));
    return result;
  }

 private:
  GroundPose pose(std::uint32_t f) const { return {root_.positions[f], root_.facings[f]}; }

  const CharacterRoot& root_;
  std::uint32_t frames_;
  bool loop_;
  GroundPose after_last_;
};

std::string where(const FeatureExtractionOptions& options, const FeatureChannel& channel) {
  return (options.source.empty() ? std::string("clip") : options.source) + ": channel '" + channel.name + "'";
}

}  // namespace

std::uint32_t offset_frames(float offset_seconds, float fps) {
  const double frames = std::round(static_cast<double>(offset_seconds) * static_cast<double>(fps));
  if (!(frames >= 1.0)) return 1;
  if (frames > 1e9) return 1000000000u;
  return static_cast<std::uint32_t>(frames);
}

std::uint32_t max_offset_frames(const FeatureSchema& schema, float fps) {
  std::uint32_t result = 0;
  for (const FeatureChannel& channel : schema.channels) {
    if (channel.kind != ChannelKind::TrajectoryPosition && channel.kind != ChannelKind::TrajectoryDirection) continue;
    for (float t : channel.offsets_seconds) result = std::max(result, offset_frames(t, fps));
  }
  return result;
}

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

  // Resolve bones once per clip (skeletons may differ between clips).
  const std::size_t joints = motion.joint_count();
  std::vector<int> channel_bone(schema.channels.size(), -1);
  std::vector<std::size_t> channel_custom(schema.channels.size(), 0);
  std::vector<bool> joint_used(joints, false);
  std::size_t custom_count = 0;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    if (channel.kind == ChannelKind::BonePosition || channel.kind == ChannelKind::BoneVelocity ||
        channel.kind == ChannelKind::RootVelocity) {
      const std::string bone = channel.bone.empty() ? std::string("@hips") : channel.bone;
      Result<int> index = find_bone(motion.skeleton, bone);
      if (!index.ok()) return make_error(where(options, channel) + ": " + index.message());
      channel_bone[c] = *index;
      joint_used[static_cast<std::size_t>(*index)] = true;
    } else if (channel.kind == ChannelKind::Custom) {
      channel_custom[c] = custom_count++;
      if (custom_count <= options.custom.size()) {
        const std::vector<float>& values = options.custom[custom_count - 1];
        if (values.size() != std::size_t{frames} * channel.custom_dims) {
          return make_error(where(options, channel) + ": custom values hold " + std::to_string(values.size()) +
                            " floats, expected " + std::to_string(frames) + " frames x " +
                            std::to_string(channel.custom_dims) + " dims");
        }
      }
    }
  }
  if (custom_count != options.custom.size()) {
    return make_error(source + ": the schema has " + std::to_string(custom_count) + " custom channels, " +
                      std::to_string(options.custom.size()) + " custom arrays were given");
  }

  // Global positions of the bones the schema reads, [frames x joints].
  std::vector<glm::vec3> global(std::size_t{frames} * joints);
  {
    std::vector<glm::vec3> positions(joints);
    std::vector<glm::quat> rotations(joints);
    for (std::uint32_t f = 0; f < frames; ++f) {
      forward_kinematics(motion, f, positions, rotations);
      std::copy(positions.begin(), positions.end(), global.begin() + static_cast<std::ptrdiff_t>(std::size_t{f} * joints));
    }
  }
  auto bone_position = [&](std::uint32_t f, int joint) { return global[std::size_t{f} * joints + static_cast<std::size_t>(joint)]; };
  auto bone_velocity = [&](std::uint32_t f, int joint) -> glm::vec3 {
    if (frames < 2) return glm::vec3(0.0f);
    if (f == 0) return (bone_position(1, joint) - bone_position(0, joint)) * motion.fps;
    if (f == frames - 1) return (bone_position(f, joint) - bone_position(f - 1, joint)) * motion.fps;
    return (bone_position(f + 1, joint) - bone_position(f - 1, joint)) * (0.5f * motion.fps);
  };

  RawFeatures out;
  out.frame_count = frames;
  out.dims = dims;
  out.values.assign(std::size_t{frames} * dims, 0.0f);
  out.past_end.assign(frames, 0);
  const Trajectory trajectory(root, frames, options.loop);
  const std::uint32_t furthest = max_offset_frames(schema, motion.fps);

  for (std::uint32_t f = 0; f < frames; ++f) {
    const glm::vec3 origin = root.positions[f];
    const glm::vec3 facing = root.facings[f];
    float* row = out.values.data() + std::size_t{f} * dims;
    if (!options.loop && furthest > 0 && std::uint64_t{f} + furthest > std::uint64_t{frames} - 1) out.past_end[f] = 1;
    for (std::size_t c = 0; c < schema.channels.size(); ++c) {
      const FeatureChannel& channel = schema.channels[c];
      switch (channel.kind) {
        case ChannelKind::TrajectoryPosition:
        case ChannelKind::TrajectoryDirection:
          for (float t : channel.offsets_seconds) {
            const GroundPose future = trajectory.at(std::uint64_t{f} + offset_frames(t, motion.fps));
            const glm::vec3 local = channel.kind == ChannelKind::TrajectoryPosition
                                        ? to_local(future.position - origin, facing)
                                        : to_local(future.facing, facing);
            *row++ = local.x;
            *row++ = local.z;
          }
          break;
        case ChannelKind::BonePosition: {
          const glm::vec3 local = to_local(bone_position(f, channel_bone[c]) - origin, facing);
          *row++ = local.x;
          *row++ = local.y;
          *row++ = local.z;
          break;
        }
        case ChannelKind::BoneVelocity:
        case ChannelKind::RootVelocity: {
          const glm::vec3 local = to_local(bone_velocity(f, channel_bone[c]), facing);
          *row++ = local.x;
          *row++ = local.y;
          *row++ = local.z;
          break;
        }
        case ChannelKind::Custom: {
          const std::vector<float>& values = options.custom[channel_custom[c]];
          const float* src = values.data() + std::size_t{f} * channel.custom_dims;
          row = std::copy(src, src + channel.custom_dims, row);
          break;
        }
      }
    }
  }
  for (std::size_t i = 0; i < out.values.size(); ++i) {
    if (!std::isfinite(out.values[i])) {
      return make_error(source + ": feature " + schema.dim_name(static_cast<std::uint32_t>(i % dims)) + " of frame " +
                        std::to_string(i / dims) + " is not finite");
    }
  }
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
  Result<std::string> bytes = detail::read_file(path);
  if (!bytes.ok()) {
    return make_error(bytes.message() + " (custom channel '" + channel.name + "' of " + bvh_path.string() + ")");
  }
  const std::size_t expected = std::size_t{frame_count} * channel.custom_dims * sizeof(float);
  if (bytes->size() != expected) {
    return make_error(path.string() + ": " + std::to_string(bytes->size()) + " bytes, expected " +
                      std::to_string(frame_count) + " frames x " + std::to_string(channel.custom_dims) +
                      " dims x 4 bytes = " + std::to_string(expected) + " (raw little-endian float32)");
  }
  std::vector<float> values(std::size_t{frame_count} * channel.custom_dims);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes->data());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::uint32_t bits = std::uint32_t{data[4 * i]} | std::uint32_t{data[4 * i + 1]} << 8 |
                               std::uint32_t{data[4 * i + 2]} << 16 | std::uint32_t{data[4 * i + 3]} << 24;
    std::memcpy(&values[i], &bits, sizeof(float));
    if (!std::isfinite(values[i])) {
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
