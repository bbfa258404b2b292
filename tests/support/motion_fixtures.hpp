// Helpers for tests on hand-made motions.
#pragma once

#include <gtest/gtest.h>

#include <string_view>

#include "mmvk/character.hpp"
#include "mmvk/features.hpp"

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

}  // namespace mmvk::test
