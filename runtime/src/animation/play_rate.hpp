// Speed from the animation (ControllerParams' play-rate and stride fields,
// crowd_controller.hpp): how fast a character plays its clip, and how far
// its root motion is stretched, so that the motion's own speed approaches
// the speed its simulated root moves at.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database.hpp"

namespace mmvk::detail {

// The played root speed below which a frame counts as standing (m/s): its
// rate stays 1, since no rate makes a standing frame walk, and so does its
// stride unless the command is to stand (speed_scale).
inline constexpr float kStandingSpeed = 0.1f;

// The speed of a velocity along the ground (its y ignored), m/s.
inline float horizontal_speed(const glm::vec3& v) { return std::sqrt(v.x * v.x + v.z * v.z); }

// Each frame's stride speed, [frames] m/s: the root's horizontal path length
// over stride_window seconds centred on the frame (clipped to its clip),
// divided by that time. A mean over about a stride, so the rate does not
// follow the root's speed up and down within each step.
std::vector<float> stride_speeds(const Database& database, float stride_window);

struct SpeedScale {
  float play_rate = 1.0f;     // clip seconds per second
  float stride_scale = 1.0f;  // root motion multiplier along the travel
};

// The play rate that brings `stride_speed` toward `target_speed` (m/s),
// within [min_play_rate, max_play_rate], then the stride scale for what is
// left, within [min_stride_scale, max_stride_scale]. On a standing frame
// (stride_speed < kStandingSpeed) the rate is 1, and so is the stride scale
// unless the command is to stand (`commanded_speed` < kStandingSpeed): then
// 0, the frame plays in place. A standing loop's root drifts (the default
// data's CMU loop creeps on about 4 cm/s), and a character told to stand
// should neither creep off the spot it stopped on nor glide back to it.
SpeedScale speed_scale(const ControllerParams& params, float stride_speed, float target_speed,
                       float commanded_speed);

// The checks of ControllerParams' play-rate, stride and correction-ratio
// fields: each finite, positive where it must be, each pair of bounds
// ordered; the message names the field.
Status check_speed_params(const ControllerParams& params);

}  // namespace mmvk::detail
