// Resampling a clip to another frame rate, keeping its duration.
#include <algorithm>
#include <cmath>
#include <string>

#include "mmvk/import/motion.hpp"

namespace mmvk {

Result<Motion> resample(const Motion& motion, float fps) {
  if (!(fps > 0.0f) || !std::isfinite(fps)) {
    return make_error("resample: target fps must be positive and finite, got " + std::to_string(fps));
  }
  if (!(motion.fps > 0.0f) || !std::isfinite(motion.fps)) {
    return make_error("resample: the motion's fps must be positive, got " + std::to_string(motion.fps));
  }
  const std::size_t joints = motion.joint_count();
  if (motion.local_positions.size() != motion.frame_count * joints ||
      motion.local_rotations.size() != motion.frame_count * joints) {
    return make_error("resample: local transforms are not sized frame_count x joints");
  }

  Motion out;
  out.skeleton = motion.skeleton;
  out.fps = fps;
  if (motion.frame_count == 0) return out;
  // The clip spans (n - 1) source frame intervals; the output covers the
  // same span with the nearest whole number of target intervals. Its last
  // sample is clamped to the source's last frame when rounding overshoots.
  const double duration = static_cast<double>(motion.frame_count - 1) / motion.fps;
  const double target_frames = std::round(duration * fps) + 1.0;
  if (target_frames > 1e9) return make_error("resample: " + std::to_string(target_frames) + " frames is too many");
  out.frame_count = static_cast<std::uint32_t>(target_frames);
  out.local_positions.resize(out.frame_count * joints);
  out.local_rotations.resize(out.frame_count * joints);
  const std::uint32_t last = motion.frame_count - 1;
  for (std::uint32_t f = 0; f < out.frame_count; ++f) {
    const double source = std::min(static_cast<double>(f) * motion.fps / fps, static_cast<double>(last));
    const std::uint32_t a = static_cast<std::uint32_t>(std::floor(source));
    const std::uint32_t b = std::min(a + 1, last);
    const float t = static_cast<float>(source - a);
    for (std::size_t j = 0; j < joints; ++j) {
      const glm::vec3& pa = motion.local_positions[motion.index(a, j)];
      const glm::vec3& pb = motion.local_positions[motion.index(b, j)];
      const glm::quat& qa = motion.local_rotations[motion.index(a, j)];
      const glm::quat& qb = motion.local_rotations[motion.index(b, j)];
      // glm::slerp takes the shorter arc, so q and -q (the same rotation)
      // interpolate the same way.
      out.local_positions[out.index(f, j)] = t == 0.0f ? pa : pa + (pb - pa) * t;
      out.local_rotations[out.index(f, j)] = t == 0.0f ? qa : glm::normalize(glm::slerp(qa, qb, t));
    }
  }
  return out;
}

}  // namespace mmvk
