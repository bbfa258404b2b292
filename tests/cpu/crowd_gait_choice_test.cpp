// The controller's gait from the command (ControllerParams::choose_gait), as
// a host drives it through CrowdSession::step on the shipped data: told to
// stand, characters stand still on standing frames, a standing loop played
// in place; told to run, they leave the walk; on data without an idle they
// rest on a held frame; a foot locked far off its pose steps onto it,
// standing or moving; a host's own gait tag is left alone.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <vector>

#include "mmvk/database/gait_bands.hpp"
#include "setup/crowd_session.hpp"
#include "setup/default_data.hpp"
#include "support/test_data.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

constexpr std::uint32_t kAgents = 4;
constexpr double kRate = 30.0;
constexpr float kStill = 0.05f;  // m/s: the issue's bound for the root and the toes of a standing character

fs::path shipped(const char* set) { return test::test_source_dir().parent_path() / "host/crowd/data" / set; }

Database open(const fs::path& manifest) {
  Result<OpenedDatabase> opened = open_database(manifest, fs::path(), [](const std::string&) {});
  EXPECT_TRUE(opened.ok()) << opened.message();
  return std::move(opened.value().database);
}

std::unique_ptr<CrowdSession> session(const Database& db) {
  CrowdSessionOptions options;
  options.agents = kAgents;
  options.backend = "fast-box";
  options.rate_hz = kRate;
  Result<std::unique_ptr<CrowdSession>> s = CrowdSession::create(db, options);
  EXPECT_TRUE(s.ok()) << s.message();
  if (!s.ok()) return nullptr;
  for (std::uint32_t b = 0; b < kAgents; ++b) EXPECT_TRUE((*s)->place(b, 4.0f * float(b), 0.0f, 0.0f).ok());
  return std::move(*s);
}

TagMask tag(const Database& db, std::string_view name) {
  const std::string names[] = {std::string(name)};
  Result<TagMask> mask = db.tag_mask(names);
  EXPECT_TRUE(mask.ok()) << mask.message();
  return mask.ok() ? *mask : 0;
}

// Steps every character at `speed` m/s along +z for `seconds` (or toward
// and facing `heading_degrees`, from +z toward +x); over the last `measured`
// seconds, calls `each(b)` per character and tick and returns the share of
// agent-ticks whose root and toes moved under kStill.
template <typename Each>
double drive(CrowdSession& s, float speed, double seconds, double measured, Each each,
             std::optional<float> heading_degrees = std::nullopt) {
  const CrowdController& c = s.controller();
  const auto toes = c.animation().contact_joints;
  const std::size_t joints = c.animation().joint_count();
  const float yaw = glm::radians(heading_degrees.value_or(0.0f));
  const std::vector<glm::vec3> velocity(kAgents, speed * glm::vec3(std::sin(yaw), 0.0f, std::cos(yaw)));
  const std::vector<float> facing(heading_degrees ? kAgents : 0, yaw);
  const int ticks = int(std::lround(seconds * kRate)), from = ticks - int(std::lround(measured * kRate));
  std::size_t still = 0, counted = 0;
  for (int t = 0; t < ticks; ++t) {
    std::vector<glm::vec3> roots(c.root_positions().begin(), c.root_positions().end());
    std::vector<glm::vec3> world(c.world_positions().begin(), c.world_positions().end());
    EXPECT_TRUE(s.step(velocity, facing).ok());
    if (t < from) continue;
    for (std::uint32_t b = 0; b < kAgents; ++b) {
      float fastest = glm::length(c.root_positions()[b] - roots[b]);
      for (const int toe : toes) {
        const std::size_t at = b * joints + std::size_t(toe);
        fastest = std::max(fastest, glm::length(c.world_positions()[at] - world[at]));
      }
      still += fastest * float(kRate) < kStill ? 1 : 0;
      ++counted;
      each(b);
    }
  }
  return double(still) / double(counted);
}

TEST(CrowdGaitChoice, ToldToStandTheyStandStillOnStandingFrames) {
  for (const char* set : {"cmu16", "cmu131"}) {
    SCOPED_TRACE(set);
    const Database db = open(shipped(set) / "manifest.json");
    const std::unique_ptr<CrowdSession> s = session(db);
    ASSERT_TRUE(s);
    const TagMask stand = tag(db, "gait:stand");
    const CrowdController& c = s->controller();
    drive(*s, 1.3f, 3.0, 0.0, [](std::uint32_t) {});
    std::size_t on_stand = 0, ticks = 0;
    const double still = drive(*s, 0.0f, 3.0, 1.5, [&](std::uint32_t b) {
      on_stand += (db.frame_tags()[c.frames()[b]] & stand) != 0 ? 1 : 0;
      ++ticks;
      EXPECT_EQ(c.gait_states()[b].phase, GaitPhase::Stand);
      EXPECT_FALSE(c.gait_constraints()[b].rest) << "the data has an idle";
    });
    EXPECT_EQ(on_stand, ticks);
    EXPECT_GE(still, 0.9);
    // The summary's figure, measured the same way over the held stand.
    EXPECT_GE(s->summary().command.standing_still_share, 0.9);
  }
}

TEST(CrowdGaitChoice, ToldToStandAStandingLoopPlaysInPlace) {
  // The default data's standing loop (CMU 16) creeps on about 4 cm/s: played
  // with its root motion, a character placed and told to stand crept off its
  // spot until the correction pulled it back, over and over (2.3 cm of root
  // path per second; 83% of such a stand's ticks still at 60 Hz).
  const Database db = open(shipped("cmu16") / "manifest.json");
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  const TagMask stand = tag(db, "gait:stand");
  drive(*s, 0.0f, 2.0, 0.0, [](std::uint32_t) {});
  std::vector<glm::vec3> last(c.root_positions().begin(), c.root_positions().end());
  std::vector<float> path(kAgents, 0.0f);
  constexpr double kMeasured = 2.0;
  std::size_t played = 0;
  drive(*s, 0.0f, kMeasured, kMeasured, [&](std::uint32_t b) {
    const glm::vec3 step = c.root_positions()[b] - last[b];
    path[b] += std::hypot(step.x, step.z);
    last[b] = c.root_positions()[b];
    // A held frame (play rate 0) does not move either.
    if ((db.frame_tags()[c.frames()[b]] & stand) == 0 || c.play_rates()[b] == 0.0f) return;
    ++played;
    EXPECT_EQ(c.stride_scales()[b], 0.0f) << "a standing frame told to stand plays in place";
  });
  EXPECT_GT(played, 0u) << "the stand plays the standing loop";
  for (std::uint32_t b = 0; b < kAgents; ++b) EXPECT_LT(path[b] / kMeasured, 0.005) << "character " << b;
}

TEST(CrowdGaitChoice, AGaitChangeAtRuntimeFollowsTheCommand) {
  const Database db = open(shipped("cmu16") / "manifest.json");
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  const TagMask stand = tag(db, "gait:stand"), walk = tag(db, "gait:walk"), run = tag(db, "gait:run");
  drive(*s, 1.3f, 3.0, 1.5, [&](std::uint32_t b) {
    EXPECT_EQ(c.gait_states()[b].band, GaitBand::Walk);
    EXPECT_EQ(db.frame_tags()[c.frames()[b]] & (stand | run), 0u) << "a walk: walk or jog frames";
  });
  drive(*s, 3.5f, 3.0, 1.5, [&](std::uint32_t b) {
    EXPECT_EQ(c.gait_states()[b].band, GaitBand::Run);
    EXPECT_EQ(db.frame_tags()[c.frames()[b]] & (stand | walk), 0u) << "a run: jog or run frames";
  });
}

TEST(CrowdGaitChoice, DataWithoutAnIdleRestsOnAHeldFrame) {
  // CMU 16's walks and jogs without the standing loop the shipped set adds.
  const fs::path dir = test::make_temp_dir();
  {
    std::ofstream manifest(dir / "manifest.json");
    manifest << R"({"fps": 30, "mirror": true, "edge_rule": "extrapolate", )"
               R"("contacts": {"enter_speed": 0.1, "exit_speed": 0.15}, "clips": [)";
    const char* takes[] = {"16_23", "16_27", "16_41", "16_43"};
    for (std::size_t i = 0; i < 4; ++i) {
      manifest << (i ? ", " : "") << R"({"file": ")" << (shipped("cmu16") / takes[i]).string() << R"(.bvh"})";
    }
    manifest << "]}";
  }
  const Database db = open(dir / "manifest.json");
  ASSERT_FALSE(measure_gait_coverage(db).can_stand());
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  drive(*s, 1.3f, 3.0, 0.0, [](std::uint32_t) {});
  std::vector<std::uint32_t> held(kAgents, kNoFrame);
  // These takes have no frame with both feet down (at the manifest's
  // contact speeds): the rest frame is the slowest stride's, feet locked.
  const double still = drive(*s, 0.0f, 3.0, 1.5, [&](std::uint32_t b) {
    EXPECT_EQ(c.resting()[b], 1);
    EXPECT_TRUE(c.gait_constraints()[b].rest);
    if (held[b] == kNoFrame) held[b] = c.frames()[b];
    EXPECT_EQ(c.frames()[b], held[b]) << "holds one frame, never walks in place";
  });
  EXPECT_GE(still, 0.9);
  fs::remove_all(dir);
}

TEST(CrowdGaitChoice, AStandingFrameThatStepsOffIsNotPlayedOn) {
  // CMU 131 at 30 Hz, told to stand after bench/tools/command_script.py's
  // walks, run and 180-degree turn: the stop finds the one-footed standing
  // frames at the start of start_walk_stop_02 (measured gait:stand, a weight
  // shift into its first step), which were never held, so each search
  // picked another and the characters shuffled (0% still). They rest now.
  const Database db = open(shipped("cmu131") / "manifest.json");
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  const auto ignore = [](std::uint32_t) {};
  const struct {
    float speed, heading;
    double seconds;
  } script[] = {{0.0f, 0.0f, 2.0}, {1.3f, 0.0f, 4.0}, {1.3f, 90.0f, 4.0},
                {0.8f, 90.0f, 4.0}, {3.0f, 90.0f, 4.0}, {1.3f, 270.0f, 4.0}};
  for (const auto& command : script) drive(*s, command.speed, command.seconds, 0.0, ignore, command.heading);
  const double still = drive(*s, 0.0f, 3.0, 1.5, [&](std::uint32_t b) { EXPECT_EQ(c.resting()[b], 1); }, 270.0f);
  EXPECT_GE(still, 0.9);
}

TEST(CrowdGaitChoice, AtRestTheFeetStepOntoTheHeldPose) {
  // Bandai locomotion (no idle): a character stopped from a walk rests
  // on a held frame; a foot locked where it planted mid-stride steps onto
  // that pose, so once it has settled every locked foot is within 11 cm of
  // its pose (the lock's correction; held, they were 27-37 cm off), and the
  // feet stand side by side rather than a stride apart. Stopped from a run,
  // it rests on the same frame: the run's own double supports are wide.
  MMVK_REQUIRE_DATA_DIR(data);
  const Database db = open(data / "bandai-namco-nc/locomotion-normal");
  ASSERT_FALSE(measure_gait_coverage(db).can_stand());
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  const auto toes = c.animation().contact_joints;
  const std::size_t joints = c.animation().joint_count();
  // The toes' distance along the facing, of the pose shown or the pose held.
  const auto spread = [&](std::span<const glm::vec3> world, std::uint32_t b) {
    const glm::vec3 apart = world[b * joints + std::size_t(toes[0])] - world[b * joints + std::size_t(toes[1])];
    const float yaw = c.root_yaws()[b];
    return std::abs(apart.x * std::sin(yaw) + apart.z * std::cos(yaw));
  };
  for (const float speed : {1.3f, 3.0f}) {
    SCOPED_TRACE(speed);
    drive(*s, speed, 3.0, 0.0, [](std::uint32_t) {});
    float farthest = 0.0f, widest = 0.0f, widest_held = 0.0f;
    const double still = drive(*s, 0.0f, 3.0, 1.5, [&](std::uint32_t b) {
      EXPECT_EQ(c.resting()[b], 1);
      for (std::size_t f = b * 2; f < b * 2 + 2; ++f) {
        if (c.foot_locked()[f]) farthest = std::max(farthest, glm::length(c.foot_corrections()[f]));
      }
      widest = std::max(widest, spread(c.world_positions(), b));
      widest_held = std::max(widest_held, spread(c.animated_world_positions(), b));
    });
    EXPECT_GE(still, 0.9);
    EXPECT_LE(farthest, 0.11f);
    // The run clips' slowest double supports are 0.5 m wide: it rests on the walk's.
    EXPECT_LT(widest_held, 0.3f) << "the frame held has its feet side by side, not a stride (0.5-0.7 m) apart";
    EXPECT_LT(widest, 0.3f) << "and so do the feet shown";
  }
}

TEST(CrowdGaitChoice, MovingAFootHeldFarOffItsPoseStepsOntoIt) {
  // Bandai locomotion, walked at 1.3 m/s and turned 180 degrees: the jump
  // into the turn blends the pose under a foot that has just locked, and the
  // lock held it up to 41 cm off its pose (the leg stretched behind, across
  // the other). A locked foot more than 10 cm off its pose steps onto it, so
  // none is held much further (the last tick's motion before the step).
  MMVK_REQUIRE_DATA_DIR(data);
  const Database db = open(data / "bandai-namco-nc/locomotion-normal");
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const CrowdController& c = s->controller();
  drive(*s, 1.3f, 4.0, 0.0, [](std::uint32_t) {}, 90.0f);
  float farthest = 0.0f;
  drive(*s, 1.3f, 4.0, 4.0, [&](std::uint32_t b) {
    for (std::size_t f = b * 2; f < b * 2 + 2; ++f) {
      const glm::vec3 off = c.foot_corrections()[f];
      if (c.foot_locked()[f]) farthest = std::max(farthest, std::hypot(off.x, off.z));
    }
  }, 270.0f);
  EXPECT_LT(farthest, 0.15f);
}

TEST(CrowdGaitChoice, AHostsOwnGaitTagIsLeftAlone) {
  const Database db = open(shipped("cmu16") / "manifest.json");
  const std::unique_ptr<CrowdSession> s = session(db);
  ASSERT_TRUE(s);
  const std::uint64_t agents[] = {0};
  const std::string walk[] = {"gait:walk"};
  ASSERT_TRUE(s->set_tags(agents, walk, {}).ok());
  const CrowdController& c = s->controller();
  std::vector<std::uint32_t> frames;
  drive(*s, 0.0f, 2.0, 1.0, [&](std::uint32_t b) {
    if (b != 0) return;
    EXPECT_EQ(c.gait_constraints()[b], GaitConstraint{});
    EXPECT_EQ(c.resting()[b], 0);
    frames.push_back(c.frames()[b]);
  });
  // Told to walk by its host, it plays on (in place), where the others stand.
  EXPECT_GT(std::set<std::uint32_t>(frames.begin(), frames.end()).size(), 3u) << "not held";
  EXPECT_EQ(c.gait_states()[1].phase, GaitPhase::Stand);
}

}  // namespace
}  // namespace mmvk::crowd
