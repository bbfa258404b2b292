// The displayed poses of the first M characters of a crowd, tick by tick,
// for the exporters (bvh_export.hpp, gltf_export.hpp): each tick's root
// (position, yaw) and local pose (rotations of every joint, translations of
// the translated joints) as CrowdController shows it, after foot IK.
//
// Conventions (those of CrowdController and docs/animation.md): metres,
// +Y up; a root is on the ground (y = 0) with yaw radians about +Y (0 faces
// +Z); a pose is in character space, so joint j's world transform is
// T(root) * R_y(yaw) * (the parents' chain) * T(translation_j) * R(rotation_j),
// with a joint's translation its skeleton rest offset unless it is one of
// the translated joints (the hips). Sample i is the pose after the i-th
// recorded tick.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// The most a pose recording may hold, and so the memory it takes: 512 MiB,
// as --trace (20 characters of 31 joints for 10 minutes at 60 Hz take 360 MiB).
inline constexpr std::uint64_t kMaxPoseRecordingBytes = std::uint64_t{512} << 20;

struct PoseRecording {
  Skeleton skeleton;
  std::vector<std::uint32_t> translated_joints;  // ascending, as AnimationData's
  double tick_rate_hz = 0.0;
  std::uint32_t agents = 0;  // recorded: the first of the crowd
  std::uint64_t ticks = 0;   // recorded so far
  std::vector<glm::vec3> root_positions;  // [ticks x agents], world, y = 0
  std::vector<float> root_yaws;           // [ticks x agents], radians
  std::vector<glm::quat> rotations;       // [ticks x agents x joints], unit, character space
  std::vector<glm::vec3> translations;    // [ticks x agents x translated joints], metres

  std::size_t joints() const { return skeleton.size(); }
  // Bytes one tick adds to the recording.
  std::uint64_t bytes_per_tick() const;
  // Joint j's local translation for `agent` at sample `tick`.
  glm::vec3 translation(std::uint64_t tick, std::uint32_t agent, std::size_t j) const;
  const glm::quat& rotation(std::uint64_t tick, std::uint32_t agent, std::size_t j) const {
    return rotations[(tick * agents + agent) * joints() + j];
  }
};

class PoseRecorder {
 public:
  // Records the first `agents` of `crowd_agents` characters over
  // `animation`'s skeleton at `tick_rate_hz`, for `ticks` ticks (0: not
  // known; every record() then checks the cap). Errors name `count_option`
  // (the option that set `agents`): 0 or more than the crowd; and
  // `size_option`: `ticks` over kMaxPoseRecordingBytes.
  static Result<PoseRecorder> create(const AnimationData& animation, std::uint32_t agents, std::uint32_t crowd_agents,
                                     double tick_rate_hz, std::uint64_t ticks, const std::string& count_option,
                                     const std::string& size_option);

  // An error naming the options when `more` ticks would take the recording
  // over kMaxPoseRecordingBytes.
  Status check_room(std::uint64_t more) const;
  // After each tick: the controller's displayed pose of the recorded
  // characters. Errors: the recording is full (check_room(1)).
  Status record(const CrowdController& controller);
  const PoseRecording& recording() const { return recording_; }

 private:
  PoseRecorder() = default;

  PoseRecording recording_;
  std::string count_option_, size_option_;
};

}  // namespace mmvk::crowd
