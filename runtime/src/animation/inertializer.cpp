// Offset-based inertialization (pose_batch.hpp): offsets recorded at a jump,
// decayed by a critically damped spring every tick.
#include <cassert>
#include <cmath>

#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/animation/spring.hpp"

namespace mmvk {

namespace {

// Below this angle (radians) the rotation vector maps use their series: the
// exact forms divide by the angle.
constexpr float kSmallAngle = 1e-4f;

}  // namespace

glm::vec3 quat_to_rotation_vector(const glm::quat& q_in) {
  // Shorter arc: q and -q are the same rotation.
  const glm::quat q = q_in.w < 0.0f ? -q_in : q_in;
  const glm::vec3 v(q.x, q.y, q.z);
  const float s = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  if (s < kSmallAngle) return v * (2.0f / std::max(q.w, 1e-6f));
  return v * (2.0f * std::atan2(s, q.w) / s);
}

glm::quat rotation_vector_to_quat(const glm::vec3& v) {
  // The offsets the inertializer applies are at most a half turn (shorter
  // arc) and decay from there, so the half angle x is almost always within
  // pi/2, where Taylor series to x^10 of cos(x) and sin(x)/x are accurate to
  // 3e-7 (the runtime's hottest function: one call per joint per character
  // per tick). Beyond it, the library functions.
  const float angle2 = v.x * v.x + v.y * v.y + v.z * v.z;
  const float x2 = 0.25f * angle2;
  if (x2 <= 2.4674011f) {  // (pi/2)^2
    const float c = 1.0f + x2 * (-1.0f / 2 + x2 * (1.0f / 24 + x2 * (-1.0f / 720 + x2 * (1.0f / 40320 + x2 * (-1.0f / 3628800)))));
    const float s = 0.5f * (1.0f + x2 * (-1.0f / 6 + x2 * (1.0f / 120 + x2 * (-1.0f / 5040 + x2 * (1.0f / 362880 + x2 * (-1.0f / 39916800))))));
    return glm::quat(c, v.x * s, v.y * s, v.z * s);
  }
  const float angle = std::sqrt(angle2);
  const float s = std::sin(0.5f * angle) / angle;
  return glm::quat(std::cos(0.5f * angle), v.x * s, v.y * s, v.z * s);
}

Inertializer::Inertializer(std::uint32_t characters, const AnimationData& animation)
    : characters_(characters),
      joints_(static_cast<std::uint32_t>(animation.joint_count())),
      translated_(animation.translated_joints) {
  const std::size_t rotations = std::size_t{characters} * joints_;
  const std::size_t translations = std::size_t{characters} * translated_.size();
  rot_offset_.assign(rotations, glm::vec3(0.0f));
  rot_velocity_.assign(rotations, glm::vec3(0.0f));
  pos_offset_.assign(translations, glm::vec3(0.0f));
  pos_velocity_.assign(translations, glm::vec3(0.0f));
  root_vel_offset_.assign(characters, glm::vec3(0.0f));
  root_acc_.assign(characters, glm::vec3(0.0f));
  yaw_rate_offset_.assign(characters, 0.0f);
  yaw_acc_.assign(characters, 0.0f);
}

void Inertializer::transition(std::uint32_t b, const PoseState& source, const PoseState& destination) {
  assert(b < characters_);
  const std::size_t base = std::size_t{b} * joints_;
  for (std::size_t j = 0; j < joints_; ++j) {
    rot_offset_[base + j] = quat_to_rotation_vector(source.rotations[j] * glm::inverse(destination.rotations[j]));
    rot_velocity_[base + j] = source.angular_velocities[j] - destination.angular_velocities[j];
  }
  const std::size_t count = translated_.size();
  for (std::size_t t = 0; t < count; ++t) {
    const std::uint32_t j = translated_[t];
    pos_offset_[b * count + t] = source.translations[j] - destination.translations[j];
    pos_velocity_[b * count + t] = source.velocities[j] - destination.velocities[j];
  }
  // The root is inertialized on its velocity: the offset is the velocity
  // difference, starting without a rate of change of its own.
  root_vel_offset_[b] = source.root_velocity - destination.root_velocity;
  root_acc_[b] = glm::vec3(0.0f);
  yaw_rate_offset_[b] = source.root_yaw_rate - destination.root_yaw_rate;
  yaw_acc_[b] = 0.0f;
}

Inertializer::RootOffset Inertializer::update(std::uint32_t b, float half_life, float dt,
                                              std::span<glm::quat> rotations, std::span<glm::vec3> translations) {
  assert(b < characters_ && rotations.size() >= joints_ && translations.size() >= joints_);
  // spring_decay written out once per character: the exponential is shared
  // by every joint.
  const float y = spring_rate(half_life);
  const float e = std::exp(-y * dt);
  const float ydt = y * dt;
  auto decay = [&](glm::vec3& x, glm::vec3& v) {
    const glm::vec3 j1 = v + x * y;
    x = (x + j1 * dt) * e;
    v = (v - j1 * ydt) * e;
  };
  const std::size_t base = std::size_t{b} * joints_;
  for (std::size_t j = 0; j < joints_; ++j) {
    glm::vec3& x = rot_offset_[base + j];
    decay(x, rot_velocity_[base + j]);
    rotations[j] = rotation_vector_to_quat(x) * rotations[j];
  }
  const std::size_t count = translated_.size();
  for (std::size_t t = 0; t < count; ++t) {
    glm::vec3& x = pos_offset_[b * count + t];
    decay(x, pos_velocity_[b * count + t]);
    translations[translated_[t]] += x;
  }
  decay(root_vel_offset_[b], root_acc_[b]);
  float& w = yaw_rate_offset_[b];
  float& a = yaw_acc_[b];
  const float j1 = a + w * y;
  w = (w + j1 * dt) * e;
  a = (a - j1 * ydt) * e;
  return {root_vel_offset_[b], w};
}

std::span<const glm::vec3> Inertializer::rotation_offsets(std::uint32_t b) const {
  return {rot_offset_.data() + std::size_t{b} * joints_, joints_};
}

std::span<const glm::vec3> Inertializer::translation_offsets(std::uint32_t b) const {
  return {pos_offset_.data() + std::size_t{b} * translated_.size(), translated_.size()};
}

std::span<const glm::vec3> Inertializer::rotation_offset_velocities(std::uint32_t b) const {
  return {rot_velocity_.data() + std::size_t{b} * joints_, joints_};
}

std::span<const glm::vec3> Inertializer::translation_offset_velocities(std::uint32_t b) const {
  return {pos_velocity_.data() + std::size_t{b} * translated_.size(), translated_.size()};
}

void Inertializer::reset(std::uint32_t b) {
  const std::size_t base = std::size_t{b} * joints_;
  for (std::size_t j = 0; j < joints_; ++j) rot_offset_[base + j] = rot_velocity_[base + j] = glm::vec3(0.0f);
  const std::size_t count = translated_.size();
  for (std::size_t t = 0; t < count; ++t) pos_offset_[b * count + t] = pos_velocity_[b * count + t] = glm::vec3(0.0f);
  root_vel_offset_[b] = root_acc_[b] = glm::vec3(0.0f);
  yaw_rate_offset_[b] = yaw_acc_[b] = 0.0f;
}

}  // namespace mmvk
