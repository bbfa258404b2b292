// Foot locking's cost per character per tick on the Bandai skeleton (22
// joints), on one core: each character plays its own stretch of Bandai
// locomotion a frame per tick with the clip's root motion and contacts, so
// feet lock, hold, release and the hips drop as they do in a crowd.
//   BM_FootLockerBaselineFK: sample the pose + forward kinematics (what a
//     controller without IK does to show a character);
//   BM_FootLockerUpdate: sample the pose + its forward kinematics +
//     FootLocker::update (IK on those world positions, as the controller
//     runs it).
// The difference of the two is what foot locking adds.
#include <benchmark/benchmark.h>

#include <vector>

#include "bench_data.hpp"
#include "mmvk/animation/foot_locker.hpp"
#include "mmvk/animation/pose_batch.hpp"

namespace mmvk::bench {

namespace {

void run_foot_locker(benchmark::State& state, bool with_ik) {
  const Database* db = database(DataSet::Locomotion);
  if (db == nullptr || db->animation() == nullptr) {
    state.SkipWithError("no database with animation (see stderr)");
    return;
  }
  const AnimationData& animation = *db->animation();
  const auto characters = static_cast<std::uint32_t>(state.range(0));
  Result<FootLocker> locker = FootLocker::create(animation, characters);
  if (!locker.ok()) {
    state.SkipWithError(locker.message().c_str());
    return;
  }
  const std::size_t joints = animation.joint_count();
  std::vector<glm::quat> rotations(std::size_t{characters} * joints);
  std::vector<glm::vec3> translations(rotations.size());
  std::vector<glm::vec3> world(rotations.size());
  std::vector<glm::vec3> animated(joints);
  std::vector<glm::vec3> roots(characters);
  std::vector<float> yaws(characters);
  std::vector<std::uint32_t> start(characters);
  for (std::uint32_t b = 0; b < characters; ++b) start[b] = (b * 7919u) % animation.frame_count;
  const float dt = 1.0f / db->fps();
  std::uint64_t tick = 0;
  std::uint64_t locked = 0;
  for (auto _ : state) {
    for (std::uint32_t b = 0; b < characters; ++b) {
      const std::uint32_t frame = static_cast<std::uint32_t>((start[b] + tick) % animation.frame_count);
      const std::span<glm::quat> r = std::span(rotations).subspan(std::size_t{b} * joints, joints);
      const std::span<glm::vec3> t = std::span(translations).subspan(std::size_t{b} * joints, joints);
      const std::span<glm::vec3> w = std::span(world).subspan(std::size_t{b} * joints, joints);
      sample_pose(animation, frame, r, t);
      roots[b] = animation.root_positions[frame];
      yaws[b] = animation.root_yaws[frame];
      if (with_ik) {
        forward_kinematics_batch(animation.skeleton, r, t, {&roots[b], 1}, {&yaws[b], 1}, animated);
        locker->update(b, dt, animation.contacts[frame], roots[b], yaws[b], animated, r, t, w);
      }
    }
    if (!with_ik) forward_kinematics_batch(animation.skeleton, rotations, translations, roots, yaws, world);
    benchmark::DoNotOptimize(world.data());
    benchmark::ClobberMemory();
    if (with_ik) {
      for (const std::uint8_t l : locker->locked()) locked += l;
    }
    ++tick;
  }
  state.counters["characters"] = characters;
  state.counters["time/character"] = benchmark::Counter(double(characters) * double(state.iterations()),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  if (with_ik) {
    state.counters["locked_feet"] = double(locked) / (2.0 * double(characters) * double(state.iterations()));
  }
}

void BM_FootLockerBaselineFK(benchmark::State& state) { run_foot_locker(state, false); }
void BM_FootLockerUpdate(benchmark::State& state) { run_foot_locker(state, true); }

}  // namespace

BENCHMARK(BM_FootLockerBaselineFK)->ArgName("characters")->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FootLockerUpdate)->ArgName("characters")->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace mmvk::bench
