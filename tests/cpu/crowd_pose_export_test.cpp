// The displayed pose as CrowdController exposes it, and its recording for
// the exporters (host/crowd/output/pose_recording.hpp), on the shipped CMU walks:
// forward kinematics of local_rotations() and local_translations() under
// root_positions() and root_yaws() is world_positions() with foot IK on, at
// 30 and 60 Hz; the recording keeps exactly that pose; its count and cap are
// refused before the run, naming the option.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "setup/default_data.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/search/reference_search.hpp"
#include "output/pose_recording.hpp"
#include "support/test_data.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

const Database& shipped_walks() {
  static const Database db = [] {
    const fs::path manifest = test::test_source_dir().parent_path() / "host/crowd/data/cmu131/manifest.json";
    Result<OpenedDatabase> opened = open_database(manifest, fs::path(), [](const std::string&) {});
    EXPECT_TRUE(opened.ok()) << opened.message();
    return std::move(opened.value().database);
  }();
  return db;
}

class DisplayedPose : public ::testing::TestWithParam<float> {};

TEST_P(DisplayedPose, ForwardKinematicsOfTheExposedPoseIsTheWorldPositions) {
  const float rate = GetParam();
  const Database& db = shipped_walks();
  constexpr std::uint32_t kCharacters = 6;
  Result<CrowdController> created = CrowdController::create(db, kCharacters);
  ASSERT_TRUE(created.ok()) << created.message();
  CrowdController& controller = *created;
  ASSERT_TRUE(controller.params().foot_ik.enabled);
  ReferenceSearch search(db);
  ThreadPool pool(1);
  const std::size_t joints = controller.animation().joint_count();
  Result<PoseRecorder> recorder =
      PoseRecorder::create(controller.animation(), 2, kCharacters, rate, 0, "--export-agents", "--gltf");
  ASSERT_TRUE(recorder.ok()) << recorder.message();

  std::vector<glm::vec3> velocities(kCharacters), fk(kCharacters * joints);
  float worst = 0.0f, moved_by_ik = 0.0f;
  std::uint32_t locked = 0;
  for (int t = 0; t < int(2 * rate); ++t) {
    for (std::uint32_t b = 0; b < kCharacters; ++b) velocities[b] = {0.2f * float(b), 0.0f, 0.8f};
    ASSERT_TRUE(controller.tick(1.0f / rate, CrowdInput{velocities, {}}, search, pool).ok());
    ASSERT_TRUE(recorder->record(controller).ok());
    const auto shown = controller.world_positions();
    forward_kinematics_batch(controller.animation().skeleton, controller.local_rotations(),
                             controller.local_translations(), controller.root_positions(), controller.root_yaws(),
                             fk, &pool);
    for (std::size_t i = 0; i < shown.size(); ++i) {
      worst = std::max(worst, glm::length(fk[i] - shown[i]));
      moved_by_ik = std::max(moved_by_ik, glm::length(controller.animated_world_positions()[i] - shown[i]));
    }
    for (const std::uint8_t l : controller.foot_locked()) locked += l;
  }
  EXPECT_LT(worst, 1e-4f) << "at " << rate << " Hz";
  // The test sees IK's changes: feet were locked, and joints moved by it.
  EXPECT_GT(locked, 0u);
  EXPECT_GT(moved_by_ik, 1e-3f);

  // The recording holds the last tick's pose as the controller exposed it.
  const PoseRecording& rec = recorder->recording();
  ASSERT_EQ(rec.ticks, std::uint64_t(2 * rate));
  for (std::uint32_t b = 0; b < rec.agents; ++b) {
    EXPECT_EQ(rec.root_positions[(rec.ticks - 1) * rec.agents + b], controller.root_positions()[b]);
    for (std::size_t j = 0; j < joints; ++j) {
      EXPECT_EQ(rec.rotation(rec.ticks - 1, b, j), controller.local_rotations()[b * joints + j]);
      EXPECT_EQ(rec.translation(rec.ticks - 1, b, j), controller.local_translations()[b * joints + j]);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Rates, DisplayedPose, ::testing::Values(30.0f, 60.0f));

TEST(PoseRecorder, RefusesACountBeyondTheCrowdAndARecordingOverTheCap) {
  const AnimationData& animation = *shipped_walks().animation();
  Result<PoseRecorder> beyond = PoseRecorder::create(animation, 9, 8, 30.0, 100, "--export-agents", "--bvh");
  ASSERT_FALSE(beyond.ok());
  EXPECT_NE(beyond.message().find("--export-agents 9 must be in [1, 8]"), std::string::npos) << beyond.message();
  EXPECT_FALSE(PoseRecorder::create(animation, 0, 8, 30.0, 100, "--export-agents", "--bvh").ok());

  Result<PoseRecorder> fits = PoseRecorder::create(animation, 1, 8, 30.0, 0, "--export-agents", "--bvh");
  ASSERT_TRUE(fits.ok()) << fits.message();
  const std::uint64_t room = kMaxPoseRecordingBytes / fits->recording().bytes_per_tick();
  EXPECT_TRUE(fits->check_room(room).ok());
  const Status over = fits->check_room(room + 1);
  ASSERT_FALSE(over.ok());
  EXPECT_NE(over.message().find("--bvh: "), std::string::npos) << over.message();
  EXPECT_NE(over.message().find("over the 512 MiB"), std::string::npos) << over.message();
  Result<PoseRecorder> too_long = PoseRecorder::create(animation, 1, 8, 30.0, room + 1, "--export-agents", "--bvh");
  EXPECT_FALSE(too_long.ok());
}

}  // namespace
}  // namespace mmvk::crowd
