// Queries measured on a shown pose (QueryAssembler::assemble_shown) give the
// database's own feature rows when the pose shown is a stored frame: every
// channel kind (bone positions and velocities, root velocity, past
// trajectory, turning rate, contacts, limb vectors, phase) is measured in
// the same space and units as the build extracted it. Bandai locomotion
// with every kind.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mmvk/features/features.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/query/query_assembly.hpp"
#include "mmvk/animation/spring.hpp"
#include "support/new_kinds_data.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

glm::vec3 to_character(const glm::vec3& v, float yaw) {
  const float c = std::cos(yaw), s = std::sin(yaw);
  return {v.x * c - v.z * s, v.y, v.x * s + v.z * c};
}

TEST(ShownQuery, AStoredFrameShownGivesItsOwnRow) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Database* db = test::locomotion_new_kinds_database(dir);
  ASSERT_NE(db, nullptr);
  const AnimationData& a = *db->animation();
  Result<QueryAssembler> assembler = QueryAssembler::create(*db);
  ASSERT_TRUE(assembler.ok()) << assembler.message();
  ASSERT_TRUE(assembler->measures_shown_poses());
  ASSERT_EQ(assembler->past_offsets().size(), 2u);
  const std::size_t joints = a.joint_count();
  const float fps = db->fps();
  const auto frame_clip = db->frame_clip();
  std::vector<glm::quat> rotations(3 * joints);
  std::vector<glm::vec3> translations(3 * joints), world(3 * joints), local(joints);
  std::vector<float> query(db->dims());
  const glm::vec3 origin(0.0f);
  const float no_yaw = 0.0f;
  int checked = 0;
  for (std::uint32_t f = 40; f + 40 < db->frame_count(); f += 97) {
    if (frame_clip[f - 31] != frame_clip[f + 31]) continue;  // interior frames: no edge effects
    // The pose at f, character space; f - 1 and f + 1 in the world.
    for (int k = 0; k < 3; ++k) {
      sample_pose(a, f - 1 + std::uint32_t(k), std::span(rotations).subspan(k * joints, joints),
                  std::span(translations).subspan(k * joints, joints));
    }
    forward_kinematics_batch(a.skeleton, std::span(rotations).subspan(joints, joints),
                             std::span(translations).subspan(joints, joints), {&origin, 1}, {&no_yaw, 1}, local);
    forward_kinematics_batch(a.skeleton, rotations, translations, std::span(a.root_positions).subspan(f - 1, 3),
                             std::span(a.root_yaws).subspan(f - 1, 3), world);
    std::vector<glm::vec3> velocities;
    for (int joint : assembler->velocity_joints()) {
      const glm::vec3 v = (world[2 * joints + std::size_t(joint)] - world[std::size_t(joint)]) * (0.5f * fps);
      velocities.push_back(to_character(v, a.root_yaws[f]));
    }
    std::vector<glm::vec3> past_positions;
    std::vector<float> past_yaws;
    for (float ago : assembler->past_offsets()) {
      const auto back = std::uint32_t(f + signed_offset_frames(-ago, fps));
      past_positions.push_back(a.root_positions[back]);
      past_yaws.push_back(a.root_yaws[back]);
    }
    std::vector<glm::vec3> future_positions;
    std::vector<float> future_yaws;
    for (float ahead : assembler->trajectory_offsets()) {
      const auto later = std::uint32_t(f + signed_offset_frames(ahead, fps));
      future_positions.push_back(a.root_positions[later]);
      future_yaws.push_back(a.root_yaws[later]);
    }
    ShownPose shown;
    shown.frame = f;
    shown.joint_positions = local;
    shown.joint_velocities = velocities;
    shown.yaw_rate = wrap_angle(a.root_yaws[f + 1] - a.root_yaws[f - 1]) * 0.5f * fps;
    shown.contacts = a.contacts[f];
    shown.past_positions = past_positions;
    shown.past_yaws = past_yaws;
    assembler->assemble_shown(shown, QueryFrame{a.root_positions[f], a.root_yaws[f]}, future_positions, future_yaws,
                              query);
    const std::span<const float> row = db->row(f);
    for (std::uint32_t d = 0; d < db->dims(); ++d) {
      // Raw units: 2 mm, 2 cm/s, 0.002 (unit vectors, rad/s): float rounding
      // of FK in another order, and the facing's smoothing against the yaw.
      const float scale = db->normalization()[d].scale;
      EXPECT_NEAR(query[d] * scale, row[d] * scale, 2e-3f) << "frame " << f << ", " << db->schema().dim_name(d);
    }
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

}  // namespace
}  // namespace mmvk
