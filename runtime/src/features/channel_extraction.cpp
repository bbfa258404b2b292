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

GroundPose Trajectory::at(std::int64_t j) const {
  const std::int64_t n = frames_;
  if (j >= 0 && j < n) return pose(static_cast<std::uint32_t>(j));
  if (!loop_) return pose(j < 0 ? 0 : frames_ - 1);
  const GroundPose first = pose(0);
  if (j >= n) {
    GroundPose result = pose(static_cast<std::uint32_t>(j % n));
    for (std::int64_t cycle = j / n; cycle > 0; --cycle) result = compose(after_last_, relative(first, result));
    return result;
  }
  // Before frame 0: the same frame of an earlier cycle, each cycle's rigid
  // motion undone (after_last_ maps back onto the first frame).
  const std::int64_t cycles = (-j + n - 1) / n;
  GroundPose result = pose(static_cast<std::uint32_t>(j + cycles * n));
  for (std::int64_t cycle = cycles; cycle > 0; --cycle) result = compose(first, relative(after_last_, result));
  return result;
}

}  // namespace mmvk::detail
