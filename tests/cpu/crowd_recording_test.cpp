// The viewer's recording of a real crowd (host/crowd/output/crowd_recorder.hpp) on
// the shipped CMU subject 16 set: the first characters' whole pose as
// displayed is kept after every tick, and every search of theirs is
// explained with the frame and the cost the search itself found.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <vector>

#include "setup/default_data.hpp"
#include "mmvk/search/async_search.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/search/reference_search.hpp"
#include "measure/tick_observers.hpp"

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

Recorded record_walk(const Database& db, std::uint32_t characters, std::uint32_t ticks) {
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
  RecordingObserver recorder(controller, scenario, "test", dt, 3);
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

TEST(CrowdRecording, TheFirstCharactersWholePosesAtTheTickRate) {
  const Database db = default_data();
  constexpr std::uint32_t kCharacters = kDefaultDetailAgents + 4, kTicks = 45;
  const Recorded recorded = record_walk(db, kCharacters, kTicks);
  const Recording& r = recorded.recording;
  ASSERT_EQ(r.detail_agents, kDefaultDetailAgents);
  ASSERT_EQ(r.detail_sample_count, kTicks);
  EXPECT_FLOAT_EQ(r.detail_rate_hz, 30.0f);
  EXPECT_EQ(r.sample_count, 15u);  // the 10 Hz samples of everyone
  const std::size_t joints = r.joint_count();
  for (std::size_t t = 0; t < kTicks; ++t) {
    for (std::size_t a = 0; a < r.detail_agents; ++a) {
      for (std::size_t j = 0; j < joints; ++j) {
        const glm::vec3& p = recorded.shown[(t * kCharacters + a) * joints + j];
        const float* q = r.detail_positions.data() + r.detail_index(t, a, j);
        ASSERT_EQ(q[0], p.x) << "tick " << t << ", character " << a << ", joint " << j;
        ASSERT_EQ(q[1], p.y);
        ASSERT_EQ(q[2], p.z);
      }
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
    if (a >= r.detail_agents) {
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
