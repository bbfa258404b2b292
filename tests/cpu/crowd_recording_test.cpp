// The viewer's recording of a real crowd (host/crowd/output/crowd_recorder.hpp) on
// the shipped CMU subject 16 set: the detailed characters' whole pose as
// displayed (the first 32 by default, or any set: --detail-agents) is kept
// after every tick, and every search of theirs is explained with the frame
// and the cost the search itself found.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <optional>
#include <vector>

#include "setup/default_data.hpp"
#include "mmvk/search/async_search.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/search/reference_search.hpp"
#include "measure/tick_observers.hpp"
#include "setup/detail_agents.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

// The default data, CMU subject 16's walks and runs, found as `mmvk crowd`
// finds it (the source tree's host/crowd/data/cmu16) and built uncached.
Database default_data() {
  const Result<DataChoice> choice = choose_data(std::nullopt, fs::path());
  EXPECT_TRUE(choice.ok()) << choice.message();
  Result<OpenedDatabase> opened = open_database(choice->source, fs::path(), [](const std::string&) {});
  EXPECT_TRUE(opened.ok()) << opened.message();
  return std::move(opened.value().database);
}

// The recording of `characters` walking for `ticks` ticks at 30 Hz, sampled
// at 10 Hz, and the displayed world joint positions after each tick.
struct Recorded {
  Recording recording;
  std::vector<glm::vec3> shown;  // [ticks x characters x joints]
};

Recorded record_walk(const Database& db, std::uint32_t characters, std::uint32_t ticks,
                     const std::optional<DetailAgents>& detail = std::nullopt) {
  Recorded out;
  Result<CrowdController> created = CrowdController::create(db, characters);
  EXPECT_TRUE(created.ok()) << created.message();
  CrowdController& controller = *created;
  Scenario scenario;
  scenario.agents.resize(characters);
  for (std::uint32_t b = 0; b < characters; ++b) {
    EXPECT_TRUE(controller.place(b, glm::vec3(2.0f * float(b), 0.0f, 0.0f), 0.0f, 10 * b).ok());
  }
  ReferenceSearch reference(db);
  DeferredSearch deferred(reference, characters);
  ThreadPool pool(1);
  const float dt = 1.0f / 30.0f;
  Result<std::vector<std::uint32_t>> chosen = resolve_detail_agents(detail, characters, "--detail-agents");
  EXPECT_TRUE(chosen.ok()) << chosen.message();
  RecordingObserver recorder(controller, scenario, "test", dt, 3, std::move(chosen.value()));
  std::vector<glm::vec3> velocities(characters);
  for (std::uint32_t t = 0; t < ticks; ++t) {
    // Turning: the searches jump now and then.
    for (std::uint32_t b = 0; b < characters; ++b) {
      const float angle = 0.02f * float(t) * float(b % 4 + 1);
      velocities[b] = {1.6f * std::sin(angle), 0.0f, 1.6f * std::cos(angle)};
    }
    EXPECT_TRUE(controller.tick(dt, CrowdInput{velocities, {}}, deferred, pool).ok());
    const auto world = controller.world_positions();
    out.shown.insert(out.shown.end(), world.begin(), world.end());
    recorder.observe(controller, {t, velocities, {}, world});
  }
  Result<Recording> finished = recorder.finish(pool);
  EXPECT_TRUE(finished.ok()) << finished.message();
  out.recording = std::move(finished.value());
  return out;
}

// The whole poses recorded are, bit for bit, what the controller displayed
// after each tick, for each detailed character in its slot.
void expect_whole_poses(const Recorded& recorded, std::size_t characters) {
  const Recording& r = recorded.recording;
  const std::size_t joints = r.joint_count();
  for (std::size_t t = 0; t < r.detail_sample_count; ++t) {
    for (std::size_t slot = 0; slot < r.detail_agents.size(); ++slot) {
      const std::size_t a = r.detail_agents[slot];
      for (std::size_t j = 0; j < joints; ++j) {
        const glm::vec3& p = recorded.shown[(t * characters + a) * joints + j];
        const float* q = r.detail_positions.data() + r.detail_index(t, slot, j);
        ASSERT_EQ(q[0], p.x) << "tick " << t << ", character " << a << ", joint " << j;
        ASSERT_EQ(q[1], p.y);
        ASSERT_EQ(q[2], p.z);
      }
    }
  }
}

TEST(CrowdRecording, TheFirstCharactersWholePosesAtTheTickRate) {
  const Database db = default_data();
  constexpr std::uint32_t kCharacters = kDefaultDetailAgents + 4, kTicks = 45;
  const Recorded recorded = record_walk(db, kCharacters, kTicks);
  const Recording& r = recorded.recording;
  ASSERT_EQ(r.detail_agents.size(), kDefaultDetailAgents);
  for (std::uint32_t a = 0; a < kDefaultDetailAgents; ++a) ASSERT_EQ(r.detail_agents[a], a);
  ASSERT_EQ(r.detail_sample_count, kTicks);
  EXPECT_FLOAT_EQ(r.detail_rate_hz, 30.0f);
  EXPECT_EQ(r.sample_count, 15u);  // the 10 Hz samples of everyone
  expect_whole_poses(recorded, kCharacters);
}

// --detail-agents 1,4-5,9 (any set): exactly those characters are kept at
// the tick rate and explained, and no other.
TEST(CrowdRecording, AChosenSetOfCharactersIsKeptInDetail) {
  const Database db = default_data();
  constexpr std::uint32_t kCharacters = 11, kTicks = 45;
  const Result<DetailAgents> spec = parse_detail_agents("9,4-5,1-1", "--detail-agents");
  ASSERT_TRUE(spec.ok()) << spec.message();
  const Recorded recorded = record_walk(db, kCharacters, kTicks, *spec);
  const Recording& r = recorded.recording;
  ASSERT_EQ(r.detail_agents, (std::vector<std::uint32_t>{1, 4, 5, 9}));
  ASSERT_EQ(r.detail_sample_count, kTicks);
  ASSERT_EQ(r.detail_positions.size(), kTicks * 4 * r.joint_count() * 3);
  expect_whole_poses(recorded, kCharacters);
  ASSERT_EQ(r.why.size(), r.agent_count);
  for (std::uint32_t a = 0; a < kCharacters; ++a) {
    const bool detailed = a == 1 || a == 4 || a == 5 || a == 9;
    EXPECT_EQ(r.why[a].size(), detailed ? r.searches[a].size() : 0u) << "character " << a;
    EXPECT_FALSE(r.searches[a].empty()) << "character " << a;
    if (!detailed) continue;
    for (std::size_t e = 0; e < r.why[a].size(); ++e) {
      ASSERT_EQ(r.why[a][e].search, e);
      EXPECT_EQ(r.why[a][e].chosen.frame, r.searches[a][e].to_frame) << "character " << a << ", search " << e;
    }
  }
}

// Each explained search: its chosen frame and cost are the search's own
// (the reference search and explain_query compute the same cost, bit for
// bit), and the cost is its channels' sum with the clip's and the
// continuing frame's terms applied.
void expect_explains(const Recording& r, const SearchEvent& event, const Recording::SearchWhy& why) {
  ASSERT_EQ(why.chosen.frame, event.to_frame);
  ASSERT_EQ(why.weights.size(), r.channel_names.size());
  if (event.to_frame < 0) return;
  EXPECT_EQ(why.chosen.cost, event.cost);
  double sum = 0.0;
  for (float c : why.chosen.weighted) sum += c;
  double cost = why.chosen.multiplier * sum + why.chosen.bias;
  if (why.chosen.frame == why.continuing.frame) cost = cost * why.continuing_multiplier + why.continuing_bias;
  EXPECT_NEAR(cost, why.chosen.cost, 1e-4 * (1.0 + std::abs(cost)));
  EXPECT_LT(why.chosen.clip, r.clip_names.size());
  // The continuing frame, when a candidate, costs no less than the winner.
  EXPECT_LT(why.continuing.exclusion, r.exclusion_names.size());
  if (why.continuing.frame >= 0 && why.continuing.exclusion == 0) {
    EXPECT_LE(why.chosen.cost, why.continuing.cost);
  }
}

TEST(CrowdRecording, EverySearchOfTheFirstCharactersIsExplained) {
  const Database db = default_data();
  constexpr std::uint32_t kCharacters = kDefaultDetailAgents + 4, kTicks = 60;
  const Recording r = record_walk(db, kCharacters, kTicks).recording;
  ASSERT_EQ(r.why.size(), r.agent_count);
  EXPECT_EQ(r.channel_names.size(), db.schema().channels.size());
  EXPECT_EQ(r.clip_names.size(), db.clips().size());
  std::size_t explained = 0, jumps = 0;
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    if (a >= r.detail_agents.size()) {
      EXPECT_TRUE(r.why[a].empty()) << "character " << a << " is not detailed";
      continue;
    }
    ASSERT_EQ(r.why[a].size(), r.searches[a].size()) << "character " << a;
    for (std::size_t e = 0; e < r.why[a].size(); ++e) {
      ASSERT_EQ(r.why[a][e].search, e);
      expect_explains(r, r.searches[a][e], r.why[a][e]);
      ++explained;
      jumps += r.searches[a][e].jumped;
    }
  }
  std::cout << "[ recording ] " << explained << " searches explained, " << jumps << " of them jumps\n";
  EXPECT_GT(explained, std::size_t{kDefaultDetailAgents} * 10);
  EXPECT_GT(jumps, 0u);
}

}  // namespace
}  // namespace mmvk::crowd
