#include "database_sliding.hpp"

#include <cmath>
#include <limits>
#include <vector>

#include "mmvk/pose_batch.hpp"

namespace mmvk::crowd {

namespace {
constexpr std::uint32_t kChunk = 4096;  // frames per FK batch (bounded memory)
}

double database_foot_sliding_cm_s(const Database& database, ThreadPool& pool) {
  const AnimationData* animation = database.animation();
  if (!animation || animation->contact_joints[0] < 0 || animation->contact_joints[1] < 0) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const std::size_t joints = animation->joint_count();
  const auto clip_of = database.frame_clip();
  std::vector<glm::quat> rotations(kChunk * joints);
  std::vector<glm::vec3> translations(kChunk * joints), world(kChunk * joints);
  // Feet of the previous frame (the last of the previous chunk included).
  glm::vec3 last_feet[2]{};
  double sum_mps = 0.0;
  std::uint64_t samples = 0;
  const double fps = database.fps();
  for (std::uint32_t first = 0; first < database.frame_count(); first += kChunk) {
    const std::uint32_t count = std::min(kChunk, database.frame_count() - first);
    for (std::uint32_t i = 0; i < count; ++i) {
      sample_pose(*animation, first + i, std::span(rotations).subspan(i * joints, joints),
                  std::span(translations).subspan(i * joints, joints));
    }
    forward_kinematics_batch(animation->skeleton, std::span(rotations).first(count * joints),
                             std::span(translations).first(count * joints),
                             std::span(animation->root_positions).subspan(first, count),
                             std::span(animation->root_yaws).subspan(first, count),
                             std::span(world).first(count * joints), &pool);
    for (std::uint32_t i = 0; i < count; ++i) {
      const std::uint32_t f = first + i;
      for (int foot = 0; foot < 2; ++foot) {
        const glm::vec3 p = world[i * joints + std::size_t(animation->contact_joints[foot])];
        const std::uint8_t bit = foot == 0 ? kContactLeft : kContactRight;
        if (f > 0 && clip_of[f] == clip_of[f - 1] && (animation->contacts[f] & bit) &&
            (animation->contacts[f - 1] & bit)) {
          const double dx = double(p.x) - last_feet[foot].x, dz = double(p.z) - last_feet[foot].z;
          sum_mps += std::sqrt(dx * dx + dz * dz) * fps;
          ++samples;
        }
        last_feet[foot] = p;
      }
    }
  }
  return samples ? 100.0 * sum_mps / double(samples) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace mmvk::crowd
