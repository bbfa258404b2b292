// Sub-frame playback: a character plays a continuous time in its clip, a
// database frame plus the fraction of the way to the next frame, so that the
// motion is the same at any tick rate and for any database fps. The pose at
// a fractional time interpolates the two neighbouring frames
// (sample_pose_at); the root moves along the clip's root path, piecewise
// linear between frames (advance_playback).
#pragma once

#include <cstdint>
#include <span>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/database/animation_data.hpp"
#include "mmvk/database/database.hpp"

namespace mmvk {

// A place in the database: `frame` plus `fraction` in [0, 1) of the way to
// next_frame(frame).
struct PlayTime {
  std::uint32_t frame = 0;
  float fraction = 0.0f;
};

// The frame played after `frame`: frame + 1 inside its clip; a looping
// clip's first frame after its last; `frame` itself on a non-looping clip's
// last frame (it is held).
std::uint32_t next_frame(const Database& database, std::uint32_t frame);

// The database frame nearest to `time` (frame, or next_frame(frame) from
// half way): the frame whose stored values stand for the time (contacts,
// copied feature channels, the continuing frame of a search).
std::uint32_t nearest_frame(const Database& database, const PlayTime& time);

// The root's motion while playing `frame` towards next_frame(frame): its
// velocity in the frame's character space (m/s) and its yaw rate (rad/s).
// A non-looping clip's last frame is held (0); a looping clip's last frame
// moves like the step into it (the root path restarts at the first frame).
RootDelta root_velocity_at(const Database& database, std::uint32_t frame);

// The result of playing on by some time.
struct PlaybackStep {
  PlayTime time;                          // where playback is now
  glm::vec3 root_translation{0.0f};       // the root's displacement, in the start's character space (metres, y = 0)
  float root_yaw = 0.0f;                  // the root's yaw change, radians
  bool reached_end = false;               // a non-looping clip's last frame was reached (and is held)
};

// Plays `frames` database frames on from `time` (frames = seconds x fps, >= 0,
// finite). The root integrates root_velocity_at() over each frame interval
// crossed. At most kMaxPlaybackSegments intervals are crossed per call: a
// longer step (a tick rate below fps / kMaxPlaybackSegments) plays only that
// far, so no call's cost depends on the size of its step.
inline constexpr std::uint32_t kMaxPlaybackSegments = 64;
PlaybackStep advance_playback(const Database& database, PlayTime time, float frames);

// The pose at a fractional time: local rotations interpolated between
// `frame` and `next` by normalized lerp along the shorter arc, local
// translations of translated joints (the hips) by lerp; sample_pose's spaces
// and sizes. fraction 0 gives exactly sample_pose(frame).
void sample_pose_at(const AnimationData& animation, std::uint32_t frame, std::uint32_t next, float fraction,
                    std::span<glm::quat> local_rotations, std::span<glm::vec3> local_translations);

}  // namespace mmvk
