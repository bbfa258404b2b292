// Helpers for tests on hand-made motions.
#pragma once

#include <gtest/gtest.h>

#include "mmvk/character.hpp"

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

}  // namespace mmvk::test
