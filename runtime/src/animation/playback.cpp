// Sub-frame playback (playback.hpp).
#include "mmvk/animation/playback.hpp"

#include <cassert>
#include <cmath>

#include "mmvk/animation/spring.hpp"
#include "yaw.hpp"

namespace mmvk {

namespace {

const Clip& clip_of(const Database& database, std::uint32_t frame) {
  return database.clips()[database.frame_clip()[frame]];
}

std::uint32_t last_frame(const Clip& clip) { return clip.first_frame + clip.frame_count - 1; }

using detail::yaw_rotate;

// The largest float below 1: a fraction that rounding pushed to 1 stays in [0, 1).
constexpr float kBelowOne = 0.99999994f;

}  // namespace

std::uint32_t next_frame(const Database& database, std::uint32_t frame) {
  const Clip& clip = clip_of(database, frame);
  if (frame < last_frame(clip)) return frame + 1;
  return clip.loop ? clip.first_frame : frame;
}

std::uint32_t nearest_frame(const Database& database, const PlayTime& time) {
  return time.fraction < 0.5f ? time.frame : next_frame(database, time.frame);
}

RootDelta root_velocity_at(const Database& database, std::uint32_t frame) {
  const AnimationData& animation = *database.animation();
  const Clip& clip = clip_of(database, frame);
  const float fps = database.fps();
  RootDelta out;
  if (frame < last_frame(clip)) {
    out = root_delta(animation, frame, frame + 1);
  } else if (clip.loop && frame > clip.first_frame) {
    // The step into the last frame, expressed in the last frame's space.
    out = root_delta(animation, frame - 1, frame);
    out.translation = yaw_rotate(out.translation, animation.root_yaws[frame - 1] - animation.root_yaws[frame]);
  } else {
    return out;  // held, or a one-frame clip
  }
  out.translation *= fps;
  out.yaw *= fps;
  return out;
}

PlaybackStep advance_playback(const Database& database, PlayTime time, float frames) {
  assert(std::isfinite(frames) && frames >= 0.0f && time.fraction >= 0.0f && time.fraction < 1.0f);
  const float seconds_per_frame = 1.0f / database.fps();
  PlaybackStep step;
  float remaining = frames;
  // Each pass plays the rest of one frame interval (or less): the count is
  // bounded by the segment cap, never by the float step's size.
  for (std::uint32_t segment = 0; segment < kMaxPlaybackSegments && remaining > 0.0f; ++segment) {
    const Clip& clip = clip_of(database, time.frame);
    if (time.frame == last_frame(clip) && !clip.loop) {
      step.reached_end = true;
      time.fraction = 0.0f;
      break;
    }
    const RootDelta velocity = root_velocity_at(database, time.frame);
    const float to_boundary = 1.0f - time.fraction;
    const float played = std::min(remaining, to_boundary);
    const float seconds = played * seconds_per_frame;
    // Between two frames the root moves along the straight chord, in the
    // direction it had at the interval's start (the yaw turns meanwhile):
    // so any split of the interval into ticks adds up to the same chord.
    const float interval_yaw = step.root_yaw - time.fraction * velocity.yaw * seconds_per_frame;
    step.root_translation += yaw_rotate(velocity.translation, interval_yaw) * seconds;
    step.root_yaw += velocity.yaw * seconds;
    if (remaining >= to_boundary) {
      remaining -= to_boundary;
      time.frame = next_frame(database, time.frame);
      time.fraction = 0.0f;
    } else {
      time.fraction = std::min(time.fraction + remaining, kBelowOne);
      remaining = 0.0f;
    }
  }
  const Clip& clip = clip_of(database, time.frame);
  if (time.frame == last_frame(clip) && !clip.loop) step.reached_end = true;
  step.root_translation.y = 0.0f;
  step.root_yaw = wrap_angle(step.root_yaw);
  step.time = time;
  return step;
}

void sample_pose_at(const AnimationData& animation, std::uint32_t frame, std::uint32_t next, float fraction,
                    std::span<glm::quat> local_rotations, std::span<glm::vec3> local_translations) {
  sample_pose(animation, frame, local_rotations, local_translations);
  if (fraction <= 0.0f || next == frame) return;
  const std::size_t joints = animation.joint_count();
  const glm::quat* to = animation.local_rotations.data() + std::size_t{next} * joints;
  const float keep = 1.0f - fraction;
  for (std::size_t j = 0; j < joints; ++j) {
    const glm::quat& a = local_rotations[j];
    // The shorter arc: q and -q are the same rotation.
    const float sign = glm::dot(a, to[j]) < 0.0f ? -1.0f : 1.0f;
    local_rotations[j] = glm::normalize(a * keep + to[j] * (sign * fraction));
  }
  const std::size_t count = animation.translated_joints.size();
  const glm::vec3* translations = animation.local_translations.data() + std::size_t{next} * count;
  for (std::size_t t = 0; t < count; ++t) {
    glm::vec3& v = local_translations[animation.translated_joints[t]];
    v = v * keep + translations[t] * fraction;
  }
}

}  // namespace mmvk
