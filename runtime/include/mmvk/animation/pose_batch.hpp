// Batched poses: forward kinematics of B characters at once into caller-owned
// spans, and offset-based inertialization of their poses. Arrays are
// character-major: [B x joints], character b's joints at [b*J, b*J + J).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

// World joint positions of B characters from character-space poses (as
// sample_pose writes them) placed at root position root_positions[b] with yaw
// root_yaws[b]: world = root + R_y(yaw) * fk(pose). Sizes: local_rotations,
// local_translations and world_positions [B x joints], roots [B]. With a pool
// the characters are split across its threads. Allocates nothing.
void forward_kinematics_batch(const Skeleton& skeleton, std::span<const glm::quat> local_rotations,
                              std::span<const glm::vec3> local_translations,
                              std::span<const glm::vec3> root_positions, std::span<const float> root_yaws,
                              std::span<glm::vec3> world_positions, ThreadPool* pool = nullptr);

// Offset-based inertialization (Bollo, GDC 2016/2018) for B characters: at a
// jump, the difference between the pose being played (source) and the new
// pose (destination) becomes an offset, with the difference of their
// velocities as its velocity; each tick the offset decays critically to zero
// (spring_decay, half-life a parameter) and is added on top of the pose
// played. So the output is continuous at the jump (offset at t = 0 = source -
// destination) and converges to the destination animation.
//
// Rotations: the offset is the rotation vector (axis * angle, shorter arc) of
// source * inverse(destination), applied as exp(offset) * played. Translated
// joints: a vec3 offset. The root's motion is inertialized on its velocity
// (character space) and yaw rate, so root position and facing stay C1.
//
// State is sized once (create); transition() and update() allocate nothing.
class Inertializer {
 public:
  Inertializer() = default;
  // `characters` x animation's joints and translated joints.
  Inertializer(std::uint32_t characters, const AnimationData& animation);

  std::uint32_t characters() const { return characters_; }

  // Character b jumps: source pose and velocity (what it would have shown
  // this tick, offsets included) to destination pose and velocity. Sizes:
  // rotations and angular velocities [joints] (rad/s, local), translations
  // [joints] (only translated joints are used), root velocities in character
  // space (m/s) and yaw rates (rad/s).
  struct PoseState {
    std::span<const glm::quat> rotations;
    std::span<const glm::vec3> angular_velocities;
    std::span<const glm::vec3> translations;
    std::span<const glm::vec3> velocities;
    glm::vec3 root_velocity{0.0f};
    float root_yaw_rate = 0.0f;
  };
  void transition(std::uint32_t b, const PoseState& source, const PoseState& destination);

  // Decays character b's offsets by dt and writes the blended pose:
  // rotations[j] = exp(offset_j) * played[j], translations likewise added.
  // `rotations` and `translations` [joints] hold the played pose on input.
  // Returns the root velocity and yaw-rate offsets to add to the played root
  // motion this tick.
  struct RootOffset {
    glm::vec3 velocity{0.0f};
    float yaw_rate = 0.0f;
  };
  RootOffset update(std::uint32_t b, float half_life, float dt, std::span<glm::quat> rotations,
                    std::span<glm::vec3> translations);

  // Character b's current offsets (tests): rotation vectors [joints] and
  // translation offsets [translated joints].
  std::span<const glm::vec3> rotation_offsets(std::uint32_t b) const;
  std::span<const glm::vec3> translation_offsets(std::uint32_t b) const;
  // Their rates of change: angular velocities [joints] (rad/s) and
  // translation velocities [translated joints] (m/s); and the root's
  // current velocity and yaw-rate offsets.
  std::span<const glm::vec3> rotation_offset_velocities(std::uint32_t b) const;
  std::span<const glm::vec3> translation_offset_velocities(std::uint32_t b) const;
  RootOffset root_offset(std::uint32_t b) const { return {root_vel_offset_[b], yaw_rate_offset_[b]}; }
  void reset(std::uint32_t b);

 private:
  std::uint32_t characters_ = 0;
  std::uint32_t joints_ = 0;
  std::vector<std::uint32_t> translated_;  // the animation's translated joints
  std::vector<glm::vec3> rot_offset_, rot_velocity_;      // [B x joints]
  std::vector<glm::vec3> pos_offset_, pos_velocity_;      // [B x translated]
  std::vector<glm::vec3> root_vel_offset_, root_acc_;     // [B]
  std::vector<float> yaw_rate_offset_, yaw_acc_;          // [B]
};

// Rotation vector (axis * angle, radians, shorter arc) of a unit quaternion,
// and its inverse.
glm::vec3 quat_to_rotation_vector(const glm::quat& q);
glm::quat rotation_vector_to_quat(const glm::vec3& v);

}  // namespace mmvk
