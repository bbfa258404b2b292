#include "measure/clip_quality.hpp"

#include <functional>
#include <vector>

#include "mmvk/animation/pose_batch.hpp"

namespace mmvk::crowd {

namespace {

constexpr std::uint32_t kChunk = 4096;  // frames per FK batch (bounded memory)

// Calls visit(frame, world joint positions [joints]) for every database
// frame in order, posed at its clip's stored root.
void for_each_frame(const Database& database, ThreadPool& pool,
                    const std::function<void(std::uint32_t, std::span<const glm::vec3>)>& visit) {
  const AnimationData& animation = *database.animation();
  const std::size_t joints = animation.joint_count();
  std::vector<glm::quat> rotations(kChunk * joints);
  std::vector<glm::vec3> translations(kChunk * joints), world(kChunk * joints);
  for (std::uint32_t first = 0; first < database.frame_count(); first += kChunk) {
    const std::uint32_t count = std::min(kChunk, database.frame_count() - first);
    for (std::uint32_t i = 0; i < count; ++i) {
      sample_pose(animation, first + i, std::span(rotations).subspan(i * joints, joints),
                  std::span(translations).subspan(i * joints, joints));
    }
    forward_kinematics_batch(animation.skeleton, std::span(rotations).first(count * joints),
                             std::span(translations).first(count * joints),
                             std::span(animation.root_positions).subspan(first, count),
                             std::span(animation.root_yaws).subspan(first, count),
                             std::span(world).first(count * joints), &pool);
    for (std::uint32_t i = 0; i < count; ++i) visit(first + i, std::span(world).subspan(i * joints, joints));
  }
}

// Median contact-joint height of each foot's flagged frames, from a 0.1 mm
// histogram over [-1, 1) m (some recordings put their ground below y = 0;
// heights outside clamp to the ends).
std::array<float, 2> planted_heights(const Database& database, const LegJoints& legs, ThreadPool& pool) {
  const AnimationData& animation = *database.animation();
  std::array<Histogram, 2> heights{Histogram(1e-4, 20000), Histogram(1e-4, 20000)};
  for_each_frame(database, pool, [&](std::uint32_t f, std::span<const glm::vec3> pose) {
    for (int foot = 0; foot < 2; ++foot) {
      if (animation.contacts[f] & (foot == 0 ? kContactLeft : kContactRight)) {
        heights[std::size_t(foot)].add(double(pose[std::size_t(legs.contact[foot])].y) + 1.0);
      }
    }
  });
  std::array<float, 2> out{0.0f, 0.0f};
  for (std::size_t foot = 0; foot < 2; ++foot) {
    if (heights[foot].count()) out[foot] = float(heights[foot].quantile(0.5) - 1.0);
  }
  return out;
}

}  // namespace

ClipQuality measure_clip_quality(const Database& database, ThreadPool& pool) {
  ClipQuality out;
  const AnimationData* animation = database.animation();
  if (!animation || database.frame_count() == 0) return out;
  MotionMeterParams params;
  params.legs = find_leg_joints(*animation);
  params.dt = 1.0 / database.fps();
  if (params.legs.has_feet()) out.planted_height = planted_heights(database, params.legs, pool);
  params.planted_height = out.planted_height;
  MotionMeter meter(1, animation->joint_count(), params);
  const auto clip_of = database.frame_clip();
  for_each_frame(database, pool, [&](std::uint32_t f, std::span<const glm::vec3> pose) {
    if (f > 0 && clip_of[f] != clip_of[f - 1]) meter.restart(0);
    meter.record({pose, {}, std::span(animation->contacts).subspan(f, 1), {}, {}, {}});
  });
  out.figures = meter.figures();
  return out;
}

}  // namespace mmvk::crowd
