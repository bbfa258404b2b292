// A crowd its caller ticks, one step() at a time: the controller, the
// deferred search and the figures of a `mmvk crowd` run (crowd_run.hpp), but
// the caller owns the loop and may steer the characters itself. Each step
// is one tick of 1 / rate_hz seconds, either
//   - step(): the crowd's own steering (seek the scenario's goals, separate
//     from neighbours; steering.hpp), as `mmvk crowd` does, or
//   - step(desired_velocity, desired_yaw): another simulator's steering,
//     handed to the controller as it is (CrowdController's CrowdInput).
// Afterwards the caller reads the characters' roots, frames, contacts and
// displayed joint positions, and at any time the run's summary (summary.hpp,
// the same figures as `mmvk crowd --summary`). The Python module's
// mmvk.Crowd is this class.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "clip_quality.hpp"
#include "crowd_backend.hpp"
#include "gait_speeds.hpp"
#include "mmvk/crowd_controller.hpp"
#include "mmvk/database.hpp"
#include "mmvk/status.hpp"
#include "mmvk/thread_pool.hpp"
#include "recording.hpp"
#include "scenario.hpp"
#include "steering.hpp"
#include "summary.hpp"
#include "tick_observers.hpp"

namespace mmvk::crowd {

// The fastest desired velocity step() takes, m/s: far beyond any motion
// capture, and far below what would overflow the search's costs.
inline constexpr float kMaxDesiredSpeed = 1000.0f;

class ObservedSearch;

struct CrowdSessionOptions {
  // The characters' starts, goals, speeds and tags; none: a random scenario
  // of `agents` characters from `seed` (as `mmvk crowd --agents N --seed S`).
  std::optional<Scenario> scenario;
  std::uint32_t agents = 100;
  std::uint64_t seed = 1;
  double rate_hz = 30.0;            // ticks per simulated second
  double search_interval_s = 0.1;   // each character's regular search period
  std::string backend = "clusters"; // a backend registry name (mmvk/backends.hpp)
  std::optional<std::uint32_t> device;  // Vulkan device index; none = the best
  bool foot_ik = true;
  // The root correction's half-life, seconds (> 0); none: the crowd's
  // default (crowd_defaults.hpp).
  std::optional<float> correction_half_life;
  // Keep the viewer's recording, for write_html().
  bool record = false;
  std::string title;                // the viewer page's header; empty: made up
};

class CrowdSession {
 public:
  // `database` must outlive the session. Errors name the option or field
  // (a database without animation, an unknown backend, a scenario asking
  // for a gait the data lacks, a bad rate).
  static Result<std::unique_ptr<CrowdSession>> create(const Database& database, const CrowdSessionOptions& options);
  ~CrowdSession();
  CrowdSession(const CrowdSession&) = delete;
  CrowdSession& operator=(const CrowdSession&) = delete;

  // One tick with the crowd's own steering.
  Status step();
  // One tick steered by the caller: desired_velocity [agents] world m/s (y
  // ignored); desired_yaw [agents] radians (0 faces +Z) or empty: face the
  // velocity. Errors: sizes, non-finite values (CrowdController::tick).
  Status step(std::span<const glm::vec3> desired_velocity, std::span<const float> desired_yaw);

  // Places character b at (x, z) facing yaw, playing `frame`; its next tick
  // searches (CrowdController::place).
  Status place(std::uint32_t b, float x, float z, float yaw, std::uint32_t frame = 0);

  std::uint32_t agents() const { return agents_; }
  double dt() const { return dt_; }
  std::uint64_t ticks() const { return ticks_; }
  const CrowdController& controller() const { return *controller_; }
  const Scenario& scenario() const { return scenario_; }
  const GaitSpeeds& speeds() const { return speeds_; }
  const std::string& device() const { return search_.device; }
  // The displayed world joint positions after the last step, [agents x
  // joints] metres (before the first step: the placed poses are not yet
  // shown, all zero).
  std::span<const glm::vec3> world_positions() const { return world_; }
  // The run so far: the figures `mmvk crowd --summary` writes.
  CrowdSummary summary() const;
  // Writes the viewer page of the steps so far (options.record); the
  // recording ends at the first call, and every later call writes the same
  // page (a retry after a failed write loses nothing). An error before the
  // first step. Returns the bytes written.
  Result<std::size_t> write_html(const std::filesystem::path& path);

 private:
  CrowdSession(const Database& database, Scenario scenario, GaitSpeeds speeds, const CrowdSessionOptions& options);
  Status tick(std::span<const glm::vec3> desired, std::span<const float> desired_yaw);

  const Database& database_;
  Scenario scenario_;
  GaitSpeeds speeds_;
  CrowdSessionOptions options_;
  std::uint32_t agents_ = 0;
  double dt_ = 0.0;
  std::uint64_t ticks_ = 0;
  ThreadPool pool_;
  std::optional<CrowdController> controller_;
  CrowdSearch search_;
  std::unique_ptr<ObservedSearch> observed_;
  std::unique_ptr<Steering> steering_;
  // The observers run_crowd has too (tick_observers.hpp).
  TickFigures figures_;
  std::unique_ptr<QualityObserver> quality_;
  std::unique_ptr<RecordingObserver> recording_;
  ControllerParams params_;
  ClipQuality clips_;

  // Per tick, sized once.
  std::vector<float> x_, z_, vx_, vz_;
  std::vector<glm::vec3> desired_, world_;
  double wall_s_ = 0.0;  // the ticks' own time, summed
  std::optional<Recording> finished_;  // the recording, once write_html ended it
};

}  // namespace mmvk::crowd
