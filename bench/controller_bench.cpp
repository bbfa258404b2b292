// The crowd controller's per-tick cost without the search, per character:
// simulation and prediction, sub-frame playback (interpolated poses),
// inertialization, root correction, the shown pose's measurements (FK of the
// animated pose), query assembly, and the displayed pose: foot locking with
// two-bone IK and its world joint positions (the NoIk variant: FK alone), on
// one core. The search is a stub that answers instantly with the jump rate
// measured on Bandai locomotion (about 3 of 4 searches jump), so the
// transitions' cost is included. Target: under 2.5 us per character with IK.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bench_data.hpp"
#include "mmvk/animation/crowd_controller.hpp"

namespace mmvk::bench {

namespace {

// Answers every query at once: 3 of 4 jump to a frame spread over the
// database, the rest continue.
class StubSearch final : public SearchBackend {
 public:
  explicit StubSearch(const Database& database) : database_(database) {}
  std::string_view name() const override { return "stub"; }
  std::string device() const override { return cpu_device_text(1); }
  const Database& database() const override { return database_; }
  Status search(const QueryBatch& batch, std::uint32_t, std::span<Match> out) override {
    for (std::size_t i = 0; i < batch.size; ++i) {
      const std::uint32_t continuing = batch.params[i].continuing_frame;
      ++calls_;
      out[i] = calls_ % 4 == 0 ? Match{continuing, 0.0f}
                               : Match{static_cast<std::uint32_t>((calls_ * 2654435761u) % database_.frame_count()), 1.0f};
    }
    return {};
  }
  SearchStats stats() const override { return {}; }
  void reset_stats() override {}

 private:
  const Database& database_;
  std::uint64_t calls_ = 0;
};

void run_controller(benchmark::State& state, bool foot_ik) {
  const Database* db = database(DataSet::Locomotion);
  if (db == nullptr) {
    state.SkipWithError("no database (see stderr)");
    return;
  }
  const auto characters = static_cast<std::uint32_t>(state.range(0));
  ControllerParams params;
  params.foot_ik.enabled = foot_ik;
  Result<CrowdController> controller = CrowdController::create(*db, characters, params);
  if (!controller.ok()) {
    state.SkipWithError(controller.message().c_str());
    return;
  }
  for (std::uint32_t b = 0; b < characters; ++b) {
    (void)controller->place(b, glm::vec3(float(b % 100), 0.0f, float(b / 100)), 0.1f * float(b),
                            (b * 7919u) % db->frame_count());
  }
  StubSearch search(*db);
  std::vector<glm::vec3> world(std::size_t{characters} * controller->animation().joint_count());
  ThreadPool pool(1);  // one core
  std::vector<glm::vec3> velocities(characters);
  const float dt = 1.0f / 30.0f;
  int tick = 0;
  std::uint64_t searches = 0;
  for (auto _ : state) {
    // Desired velocities turn slowly, as steering would make them.
    for (std::uint32_t b = 0; b < characters; ++b) {
      const float angle = 0.3f * float(b) + 0.02f * float(tick);
      velocities[b] = glm::vec3(1.4f * std::sin(angle), 0.0f, 1.4f * std::cos(angle));
    }
    Status status = controller->tick(dt, CrowdInput{velocities, {}}, search, pool);
    if (!status.ok()) {
      state.SkipWithError(status.message().c_str());
      return;
    }
    // Copied out, as a host sending poses to a renderer would.
    const auto shown = controller->world_positions();
    std::copy(shown.begin(), shown.end(), world.begin());
    benchmark::DoNotOptimize(world.data());
    searches += controller->last_tick().searches;
    ++tick;
  }
  state.counters["characters"] = characters;
  state.counters["time/character"] = benchmark::Counter(double(characters) * double(state.iterations()),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["queries/tick"] = double(searches) / double(state.iterations());
}

void BM_ControllerTick(benchmark::State& state) { run_controller(state, true); }
void BM_ControllerTickNoIk(benchmark::State& state) { run_controller(state, false); }

}  // namespace

BENCHMARK(BM_ControllerTick)->ArgName("characters")->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ControllerTickNoIk)->ArgName("characters")->Arg(1000)->Arg(10000)->Unit(benchmark::kMicrosecond);

}  // namespace mmvk::bench
