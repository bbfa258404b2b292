#include "features/channel_extraction.hpp"

#include <algorithm>
#include <cmath>

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

// The one-frame step S that, repeated `frames` times, moves `from` onto
// `to`: a constant speed and turning rate. S turns by alpha = theta / frames
// (theta: the facing change) and its translation s solves
// sum_i R(i alpha) s = d (d: the whole move in `from`'s frame), where the
// sum of rotations is [[C, S], [-S, C]] with C = sum cos(i alpha), S = sum
// sin(i alpha), inverted directly.
GroundPose constant_step(const GroundPose& from, const GroundPose& to, std::uint32_t frames) {
  const GroundPose whole = relative(from, to);
  const float alpha = std::atan2(whole.facing.x, whole.facing.z) / float(frames);
  float c = 0.0f, s = 0.0f;
  for (std::uint32_t i = 0; i < frames; ++i) c += std::cos(float(i) * alpha), s += std::sin(float(i) * alpha);
  const float det = c * c + s * s;  // |sin(frames alpha / 2) / sin(alpha / 2)|^2 >= 1 while |theta| <= pi
  const glm::vec3 d = whole.position;
  return {glm::vec3((c * d.x - s * d.z) / det, 0.0f, (s * d.x + c * d.z) / det),
          glm::vec3(std::sin(alpha), 0.0f, std::cos(alpha))};
}

}  // namespace

Trajectory::Trajectory(const CharacterRoot& root, std::uint32_t frames, bool loop, std::uint32_t extrapolate_frames)
    : root_(root), frames_(frames), loop_(loop) {
  if (loop_ && frames_ > 0) {
    const GroundPose last = pose(frames_ - 1);
    const GroundPose step = frames_ >= 2 ? relative(pose(frames_ - 2), last) : GroundPose{};
    after_last_ = compose(last, step);
  }
  if (!loop_ && extrapolate_frames > 0 && frames_ >= 2) {
    extrapolate_ = true;
    const std::uint32_t w = std::min(extrapolate_frames, frames_ - 1);
    step_after_ = constant_step(pose(frames_ - 1 - w), pose(frames_ - 1), w);
    step_before_ = constant_step(pose(w), pose(0), w);
  }
}

GroundPose Trajectory::at(std::int64_t j) const {
  const std::int64_t n = frames_;
  if (j >= 0 && j < n) return pose(static_cast<std::uint32_t>(j));
  if (extrapolate_) {
    GroundPose result = pose(j < 0 ? 0 : frames_ - 1);
    const GroundPose& step = j < 0 ? step_before_ : step_after_;
    for (std::int64_t k = j < 0 ? -j : j - (n - 1); k > 0; --k) result = compose(result, step);
    return result;
  }
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
