// What a channel kind's extractor reads and writes (see mmvk/features/channel_kinds.hpp):
// the clip's motion measured once (global joint positions, the root and its
// future poses) and one channel's place in the output matrix. Extractors are
// pure functions of this; extract_features() in features.cpp builds it.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/import/motion.hpp"

namespace mmvk::detail {

// A character root on the ground: position (y = 0) and unit facing in XZ.
struct GroundPose {
  glm::vec3 position{0.0f};
  glm::vec3 facing{0.0f, 0.0f, 1.0f};
};

// World vector -> character space of a root facing `facing` (+Z forward, +X left).
inline glm::vec3 to_local(const glm::vec3& v, const glm::vec3& facing) {
  return {v.x * facing.z - v.z * facing.x, v.y, v.x * facing.x + v.z * facing.z};
}

// Past and future root poses, looping, clamped or extrapolated. For a
// looping clip the frame after the last is the last advanced by the clip's
// final step; every further cycle repeats the rigid motion from frame 0 to
// that frame, and every cycle before frame 0 undoes it. A non-looping clip
// clamps to its first and last frames, unless `extrapolate_frames` > 0: then
// it goes on past its last frame at the constant speed and turning rate of
// its last `extrapolate_frames` frames (cut to the clip), and before its
// first frame at those of its first ones, so that a short take's last second
// still says where the character was heading.
class Trajectory {
 public:
  Trajectory(const CharacterRoot& root, std::uint32_t frames, bool loop, std::uint32_t extrapolate_frames = 0);

  // Root pose `j` frames from the start (j may run past either end).
  GroundPose at(std::int64_t j) const;

 private:
  GroundPose pose(std::uint32_t f) const { return {root_.positions[f], root_.facings[f]}; }

  const CharacterRoot& root_;
  std::uint32_t frames_;
  bool loop_;
  bool extrapolate_ = false;
  GroundPose after_last_;
  // Extrapolation: one frame's rigid step, relative to the pose it starts
  // from, forward past the last frame and backward before the first.
  GroundPose step_after_;
  GroundPose step_before_;
};

// One clip, measured once for all of its channels.
struct ClipSamples {
  const Motion& motion;
  const CharacterRoot& root;
  Trajectory trajectory;
  std::vector<glm::vec3> global;      // [frames x joints] global joint positions
  bool loop = false;
  std::vector<std::uint8_t> contacts;  // [frames] FootContact bits, when a channel reads Contacts

  std::uint32_t frames() const { return motion.frame_count; }

  // The clip frame a window sample `f + delta` reads: wrapped on a looping
  // clip, clamped to the first or last frame otherwise (the edge rule).
  std::uint32_t window_frame(std::uint32_t f, std::int64_t delta) const {
    const std::int64_t n = frames();
    std::int64_t g = std::int64_t{f} + delta;
    if (loop) {
      g %= n;
      if (g < 0) g += n;
    } else {
      g = g < 0 ? 0 : (g >= n ? n - 1 : g);
    }
    return static_cast<std::uint32_t>(g);
  }

  glm::vec3 bone_position(std::uint32_t f, int joint) const {
    return global[std::size_t{f} * motion.joint_count() + static_cast<std::size_t>(joint)];
  }

  // Finite differences of global positions: central inside the clip,
  // one-sided on its first and last frame, 0 for a one-frame clip.
  glm::vec3 bone_velocity(std::uint32_t f, int joint) const {
    const std::uint32_t n = frames();
    if (n < 2) return glm::vec3(0.0f);
    if (f == 0) return (bone_position(1, joint) - bone_position(0, joint)) * motion.fps;
    if (f == n - 1) return (bone_position(f, joint) - bone_position(f - 1, joint)) * motion.fps;
    return (bone_position(f + 1, joint) - bone_position(f - 1, joint)) * (0.5f * motion.fps);
  }
};

// A phase channel's source curve, resolved on one clip.
struct CurveSource {
  enum class Kind : std::uint8_t { Speed, Height, Column };
  Kind kind = Kind::Speed;
  int joint = -1;            // Speed, Height
  std::uint32_t column = 0;  // Column: a dimension of an earlier channel
};

// One channel of one clip: its resolved inputs and where its values go.
struct ChannelExtraction {
  const ClipSamples& clip;
  const FeatureChannel& channel;
  int bone = -1;                  // joint index, when the kind reads Bone
  int second_bone = -1;           // joint index, when the kind reads SecondBone
  std::span<const float> custom;  // [frames x custom_dims] sidecar values, when the kind reads Dims
  std::span<const CurveSource> curves;  // one per channel.curves, when the kind reads Curves
  const float* features = nullptr;      // the clip's whole matrix: column c of frame f at features[f * stride + c]
  float* out = nullptr;           // dim i of frame f goes to out[f * stride + i]
  std::uint32_t stride = 0;       // the schema's dims

  float* row(std::uint32_t f) const { return out + std::size_t{f} * stride; }
};

// The Phase kind's extractor (phase_features.cpp).
void extract_phase(const ChannelExtraction& job);

}  // namespace mmvk::detail
