#include "features/channel_extraction.hpp"

namespace mmvk::detail {

namespace {

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

}  // namespace

Trajectory::Trajectory(const CharacterRoot& root, std::uint32_t frames, bool loop)
    : root_(root), frames_(frames), loop_(loop) {
  if (loop_ && frames_ > 0) {
    const GroundPose last = pose(frames_ - 1);
    const GroundPose step = frames_ >= 2 ? relative(pose(frames_ - 2), last) : GroundPose{};
    after_last_ = compose(last, step);
  }
}

GroundPose Trajectory::at(std::uint64_t j) const {
  if (j < frames_) return pose(static_cast<std::uint32_t>(j));
  if (!loop_) return pose(frames_ - 1);
  GroundPose result = pose(static_cast<std::uint32_t>(j % frames_));
  const GroundPose first = pose(0);
  for (std::uint64_t cycle = j / frames_; cycle > 0; --cycle) result = compose(after_last_, relative(first, result));
  return result;
}

}  // namespace mmvk::detail
