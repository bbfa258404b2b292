// Helpers for tests on hand-made motions.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string_view>

#include <glm/gtc/quaternion.hpp>

#include "mmvk/import/character.hpp"
#include "mmvk/features/features.hpp"

namespace mmvk::test {

// The character root with no facing smoothing, so a hand-made motion's
// facing is exact on every frame (a failure is reported, and the root is
// then empty).
inline CharacterRoot root_of(const Motion& motion) {
  CharacterRootOptions options;
  options.facing_smoothing_seconds = 0.0f;
  Result<CharacterRoot> root = compute_character_root(motion, options);
  EXPECT_TRUE(root.ok()) << root.message();
  return root.ok() ? std::move(root).value() : CharacterRoot{};
}

// The value of schema dimension `name` ("trajectory_position[1].z") at frame f.
inline float feature(const RawFeatures& raw, const FeatureSchema& schema, std::uint32_t f, std::string_view name) {
  for (std::uint32_t d = 0; d < schema.dims(); ++d) {
    if (schema.dim_name(d) == name) return raw.values[std::size_t{f} * raw.dims + d];
  }
  ADD_FAILURE() << "no dimension " << name;
  return 0.0f;
}

// A 30 fps walker with Bandai-style names so the bone roles resolve: Hips,
// UpperLeg_L/R, Foot_L/R. The character walks along `heading` (radians from +Z towards +X) at `speed`
// m/s while turning at `turn_rate` rad/s; legs swing with `swing` radians.
inline Motion walker(std::uint32_t frames, float speed, float heading, float turn_rate = 0.0f, float swing = 0.0f) {
  Motion m;
  m.skeleton.names = {"Hips", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R"};
  m.skeleton.parents = {-1, 0, 1, 0, 3};
  m.skeleton.rest_offsets = {glm::vec3(0, 1, 0), glm::vec3(0.1f, -0.05f, 0), glm::vec3(0, -0.9f, 0),
                             glm::vec3(-0.1f, -0.05f, 0), glm::vec3(0, -0.9f, 0)};
  m.fps = 30.0f;
  m.frame_count = frames;
  glm::vec3 position(0.0f, 1.0f, 0.0f);
  float yaw = heading;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const float t = float(f) / 30.0f;
    const glm::quat hips = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
    const float phase = std::sin(2.0f * 3.14159265f * 1.5f * t);
    const glm::quat left = glm::angleAxis(swing * phase, glm::vec3(1, 0, 0));
    const glm::quat right = glm::angleAxis(-swing * phase, glm::vec3(1, 0, 0));
    const glm::quat identity(1, 0, 0, 0);
    for (std::size_t j = 0; j < 5; ++j) m.local_positions.push_back(j == 0 ? position : m.skeleton.rest_offsets[j]);
    for (const glm::quat& q : {hips, left, identity, right, identity}) m.local_rotations.push_back(q);
    position += glm::vec3(std::sin(yaw), 0.0f, std::cos(yaw)) * (speed / 30.0f);
    yaw += turn_rate / 30.0f;
  }
  return m;
}

}  // namespace mmvk::test
