// The --trace files (host/crowd/output/trace.hpp) on the shipped CMU walks: what a
// controller showed is written and read back exactly, and the checks that
// run before a simulation refuse what would fail at its end.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "setup/default_data.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/search/reference_search.hpp"
#include "support/test_data.hpp"
#include "output/trace.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

Database shipped_walks() {
  const fs::path manifest = test::test_source_dir().parent_path() / "host/crowd/data/cmu131/manifest.json";
  Result<OpenedDatabase> opened = open_database(manifest, fs::path(), [](const std::string&) {});
  EXPECT_TRUE(opened.ok()) << opened.message();
  return std::move(opened.value().database);
}

TEST(CrowdTrace, RoundTripsWhatTheControllerShowed) {
  const Database db = shipped_walks();
  constexpr std::uint32_t kCharacters = 5, kTraced = 3, kTicks = 40;
  Result<CrowdController> created = CrowdController::create(db, kCharacters);
  ASSERT_TRUE(created.ok()) << created.message();
  CrowdController& controller = *created;
  ReferenceSearch search(db);
  ThreadPool pool(1);
  const AnimationData& animation = controller.animation();
  const std::size_t joints = animation.joint_count();
  const fs::path path = test::make_temp_dir() / "walk.f32";
  const TraceLayout layout{kTicks, kTraced, std::uint32_t(joints), 60.0};
  Result<TraceWriter> writer = TraceWriter::create(path, layout, animation.skeleton, animation.contact_joints,
                                                   kCharacters);
  ASSERT_TRUE(writer.ok()) << writer.message();

  std::vector<glm::vec3> velocities(kCharacters), world(kCharacters * joints), shown;
  std::vector<std::uint8_t> contacts, locks;
  for (std::uint32_t t = 0; t < kTicks; ++t) {
    for (std::uint32_t b = 0; b < kCharacters; ++b) velocities[b] = {0.3f * float(b), 0.0f, 1.2f};
    ASSERT_TRUE(controller.tick(1.0f / 60.0f, CrowdInput{velocities, {}}, search, pool).ok());
    const auto displayed = controller.world_positions();
    world.assign(displayed.begin(), displayed.end());
    writer->record(world, controller.contacts(), controller.foot_locked());
    shown.insert(shown.end(), world.begin(), world.begin() + std::ptrdiff_t(kTraced * joints));
    for (std::uint32_t b = 0; b < kTraced; ++b) {
      contacts.push_back(controller.contacts()[b]);
      locks.push_back(std::uint8_t(controller.foot_locked()[2 * b] | (controller.foot_locked()[2 * b + 1] << 1)));
    }
  }
  ASSERT_TRUE(writer->finish().ok());
  EXPECT_EQ(fs::file_size(path), std::uint64_t{kTicks} * kTraced * joints * 12);

  Result<Trace> read = read_trace(path);
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(read->layout.ticks, kTicks);
  EXPECT_EQ(read->layout.agents, kTraced);
  EXPECT_EQ(read->layout.joints, joints);
  EXPECT_EQ(read->layout.tick_rate_hz, 60.0);
  EXPECT_EQ(read->joint_names, animation.skeleton.names);
  EXPECT_EQ(read->parents, std::vector<int>(animation.skeleton.parents.begin(), animation.skeleton.parents.end()));
  EXPECT_EQ(read->contact_joints, animation.contact_joints);
  ASSERT_EQ(read->positions.size(), shown.size() * 3);
  // Bit for bit: float32 written and read as float32.
  EXPECT_EQ(std::memcmp(read->positions.data(), shown.data(), read->positions.size() * sizeof(float)), 0);
  EXPECT_EQ(read->contacts, contacts);
  EXPECT_EQ(read->foot_locks, locks);
  // The walk is flagged in contact somewhere: the contacts are not all zero.
  EXPECT_NE(std::count(contacts.begin(), contacts.end(), 0), std::ptrdiff_t(contacts.size()));
}

TEST(CrowdTrace, RefusesBeforeTheRunWhatWouldFailAtItsEnd) {
  Skeleton skeleton;
  skeleton.names = {"hips", "\xff\xfe bad utf-8"};
  skeleton.parents = {-1, 0};
  skeleton.rest_offsets = {glm::vec3(0.0f), glm::vec3(0.0f, -0.5f, 0.0f)};
  const fs::path dir = test::make_temp_dir();
  const TraceLayout layout{10, 2, 2, 30.0};
  auto create = [&](const fs::path& path, const TraceLayout& l, std::uint32_t crowd) {
    return TraceWriter::create(path, l, skeleton, {-1, -1}, crowd);
  };
  Result<TraceWriter> beyond = create(dir / "t.f32", layout, 1);
  ASSERT_FALSE(beyond.ok());
  EXPECT_NE(beyond.message().find("--trace-agents 2 must be in [1, 1]"), std::string::npos) << beyond.message();
  Result<TraceWriter> missing = create(dir / "no-such-folder" / "t.f32", layout, 4);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("--trace"), std::string::npos) << missing.message();
  EXPECT_NE(missing.message().find("no-such-folder"), std::string::npos) << missing.message();
  Result<TraceWriter> folder = create(dir, layout, 4);
  EXPECT_FALSE(folder.ok());
  // 10 million ticks x 2 agents x 100 joints x 12 bytes: 22 GiB.
  Result<TraceWriter> huge = create(dir / "t.f32", TraceLayout{10'000'000, 2, 100, 30.0}, 4);
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.message().find("MiB a trace may take"), std::string::npos) << huge.message();

  // Invalid UTF-8 in a joint name is replaced, not thrown; the sidecar reads back.
  Result<TraceWriter> writer = create(dir / "t.f32", layout, 2);
  ASSERT_TRUE(writer.ok()) << writer.message();
  const std::vector<glm::vec3> world(4, glm::vec3(1.0f, 2.0f, 3.0f));
  const std::vector<std::uint8_t> contacts{1, 2};
  for (int t = 0; t < 10; ++t) writer->record(world, contacts, {});
  ASSERT_TRUE(writer->finish().ok());
  Result<Trace> read = read_trace(dir / "t.f32");
  ASSERT_TRUE(read.ok()) << read.message();
  EXPECT_EQ(read->joint_names[1], "\xef\xbf\xbd\xef\xbf\xbd bad utf-8");
  EXPECT_EQ(read->foot_locks, std::vector<std::uint8_t>(20, 0));

  // A positions file cut short is an error naming it.
  fs::resize_file(dir / "t.f32", 12);
  Result<Trace> cut = read_trace(dir / "t.f32");
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.message().find("expected 480"), std::string::npos) << cut.message();
}

}  // namespace
}  // namespace mmvk::crowd
