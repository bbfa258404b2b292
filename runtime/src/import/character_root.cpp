// The character root ("simulation bone"): the source bone projected to the
// ground, facing perpendicular to the hip-to-hip axis, smoothed over time.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mmvk/import/character.hpp"

namespace mmvk {

Result<CharacterRoot> compute_character_root(const Motion& motion, const CharacterRootOptions& options) {
  if (!(options.facing_smoothing_seconds >= 0.0f) || !std::isfinite(options.facing_smoothing_seconds)) {
    return make_error("character root: facing_smoothing_seconds must be >= 0, got " +
                      std::to_string(options.facing_smoothing_seconds));
  }
  const std::size_t expected = motion.frame_count * motion.joint_count();
  if (motion.local_positions.size() != expected || motion.local_rotations.size() != expected ||
      motion.skeleton.parents.size() != motion.joint_count()) {
    return make_error("character root: the motion's transforms are not sized frame_count x joints");
  }
  if (!(motion.fps > 0.0f) || !std::isfinite(motion.fps)) {
    return make_error("character root: the motion's fps must be positive, got " + std::to_string(motion.fps));
  }
  const Result<int> source = find_bone(motion.skeleton, options.source_bone);
  if (!source) return make_error("character root: source bone: " + source.message());
  const Result<int> left = find_bone(motion.skeleton, "@left_upper_leg");
  if (!left) return make_error("character root: facing needs the upper legs: " + left.message());
  const Result<int> right = find_bone(motion.skeleton, "@right_upper_leg");
  if (!right) return make_error("character root: facing needs the upper legs: " + right.message());

  const std::size_t frames = motion.frame_count;
  const std::size_t joints = motion.joint_count();
  CharacterRoot root;
  root.positions.resize(frames);
  root.facings.resize(frames);
  std::vector<glm::vec3> raw_facing(frames);
  std::vector<glm::vec3> positions(joints);
  std::vector<glm::quat> rotations(joints);
  for (std::uint32_t f = 0; f < frames; ++f) {
    forward_kinematics(motion, f, positions, rotations);
    const glm::vec3 hips = positions[static_cast<std::size_t>(*source)];
    root.positions[f] = glm::vec3(hips.x, 0.0f, hips.z);
    // Forward = (right hip -> left hip) x up, which for a character whose
    // left is +X gives +Z. Projected to the ground by construction.
    const glm::vec3 across = positions[static_cast<std::size_t>(*left)] - positions[static_cast<std::size_t>(*right)];
    const glm::vec3 forward(-across.z, 0.0f, across.x);
    const float length = glm::length(forward);
    raw_facing[f] = length > 1e-6f ? forward / length : glm::vec3(0.0f);
  }

  // Centred moving average of the unit facings over the window (shrunk at the
  // clip's ends), renormalized. Averaging unit vectors rather than angles
  // needs no unwrapping at +-180 degrees.
  const std::size_t half =
      static_cast<std::size_t>(std::lround(0.5 * static_cast<double>(options.facing_smoothing_seconds) * motion.fps));
  std::vector<glm::dvec3> prefix(frames + 1, glm::dvec3(0.0));
  for (std::size_t f = 0; f < frames; ++f) prefix[f + 1] = prefix[f] + glm::dvec3(raw_facing[f]);
  glm::vec3 previous(0.0f, 0.0f, 1.0f);
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t begin = f > half ? f - half : 0;
    const std::size_t end = std::min(frames, f + half + 1);
    const glm::dvec3 sum = prefix[end] - prefix[begin];
    const double length = glm::length(sum);
    // A degenerate window (legs aligned with up, or opposite facings that
    // cancel) keeps the previous facing.
    const glm::vec3 facing = length > 1e-9 ? glm::vec3(sum / length) : previous;
    root.facings[f] = facing;
    previous = facing;
  }
  return root;
}

}  // namespace mmvk
