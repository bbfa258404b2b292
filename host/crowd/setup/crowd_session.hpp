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
// the same figures as `mmvk crowd --summary`). `mmvk crowd` (crowd_run.hpp)
// is this class stepped by its own loop; the Python module's mmvk.Crowd is
// this class stepped from Python.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "measure/clip_quality.hpp"
#include "backends/crowd_backend.hpp"
#include "setup/crowd_limits.hpp"
#include "setup/crowd_settings.hpp"
#include "steering/gait_speeds.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "output/recording.hpp"
#include "steering/scenario.hpp"
#include "steering/steering.hpp"
#include "measure/summary.hpp"
#include "measure/tick_observers.hpp"

namespace mmvk::crowd {

// The fastest desired velocity step() takes, m/s: far beyond any motion
// capture, and far below what would overflow the search's costs.
inline constexpr float kMaxDesiredSpeed = 1000.0f;

// The crowd's settings (crowd_settings.hpp: the defaults and bounds every
// entry point shares) and what a session adds.
struct CrowdSessionOptions : CrowdSettings {
  // How errors name the settings: mmvk.Crowd's keywords, or `mmvk crowd`'s flags.
  SettingNames names = SettingNames::Keywords;
  // The characters' starts, goals, speeds and tags; none: a random scenario
  // of `agents` characters from `seed` (as `mmvk crowd --agents N --seed S`).
  std::optional<Scenario> scenario;
  // What the caller keeps besides the characters, for the memory check.
  RunOutputs outputs;
  // Keep the viewer's recording, for write_html().
  bool record = false;
  // The viewer page's header; empty: "N agents · <data_label> · <backend> on <device>".
  std::string title;
  std::string data_label;
  // The data in messages (a file or a shipped set's name); empty: "the database".
  std::string data_source;
  // The Vulkan pipeline cache's folder; empty: none (crowd_backend.hpp).
  std::filesystem::path cache_dir;
};

class CrowdSession {
 public:
  // `database` must outlive the session. Checks every setting (validate(),
  // then against the data: the memory, the costs) before it allocates for
  // them. Errors name the setting or field (a database without animation,
  // an unknown backend, a scenario asking for a gait the data lacks, a bad
  // rate, an unknown key in the data's crowd settings).
  static Result<std::unique_ptr<CrowdSession>> create(const Database& database, const CrowdSessionOptions& options);
  ~CrowdSession();
  CrowdSession(const CrowdSession&) = delete;
  CrowdSession& operator=(const CrowdSession&) = delete;

  // One tick with the crowd's own steering.
  Status step();
  // One tick steered by the caller: desired_velocity [agents] world m/s (y
  // ignored); desired_yaw [agents] radians (0 faces +Z) or empty: face the
  // velocity. Errors: sizes, non-finite values (CrowdController::tick).
  // From the first such step the controller chooses each character's gait
  // from its command (ControllerParams::choose_gait, on data with measured
  // gait tags): the scenario's walk or run tag, which keeps the crowd's own
  // walkers on the walk clips, is lifted.
  Status step(std::span<const glm::vec3> desired_velocity, std::span<const float> desired_yaw);

  // The tags characters `agents` search with from their next search on
  // (QueryParams::require_all and exclude_any, replaced): a host changes a
  // character's gait (the measured "gait:stand", "gait:walk", ... of
  // mmvk/database/gait_bands.hpp) or style at any tick. Errors, before
  // anything changes: an agent out of range, an unknown tag (listing the
  // database's tags), a tag both required and excluded.
  Status set_tags(std::span<const std::uint64_t> agents, std::span<const std::string> require,
                  std::span<const std::string> exclude);

  // Places character b at (x, z) facing yaw, playing `frame`; its next tick
  // searches (CrowdController::place).
  Status place(std::uint32_t b, float x, float z, float yaw, std::uint32_t frame = 0);

  std::uint32_t agents() const { return agents_; }
  double dt() const { return dt_; }
  double rate_hz() const { return options_.rate_hz; }
  std::uint64_t ticks() const { return ticks_; }
  const CrowdController& controller() const { return *controller_; }
  const Scenario& scenario() const { return scenario_; }
  const GaitSpeeds& speeds() const { return speeds_; }
  const std::string& device() const { return search_.device; }
  const CrowdSearch& search() const { return search_; }
  const ControllerParams& params() const { return params_; }
  // Milliseconds the last step was blocked on its search.
  double last_search_ms() const { return figures_.last_search_ms(); }
  // The displayed world joint positions after the last step, [agents x
  // joints] metres (before the first step: the placed poses).
  std::span<const glm::vec3> world_positions() const { return controller_->world_positions(); }
  // The run so far: the figures `mmvk crowd --summary` writes.
  CrowdSummary summary() const;
  // Writes the viewer page of the steps so far (options.record); the
  // recording ends at the first call, and every later call writes the same
  // page (a retry after a failed write loses nothing). An error before the
  // first step. Returns the bytes written.
  Result<std::size_t> write_html(const std::filesystem::path& path);

 private:
  CrowdSession(const Database& database, Scenario scenario, GaitSpeeds speeds, const CrowdSessionOptions& options);
  Status set_up(const ControllerParams& params);
  Status tick(std::span<const glm::vec3> desired, std::span<const float> desired_yaw,
              std::chrono::steady_clock::time_point tick_start);

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
  std::unique_ptr<Steering> steering_;
  // The observers run_crowd has too (tick_observers.hpp).
  TickFigures figures_;
  std::unique_ptr<QualityObserver> quality_;
  std::unique_ptr<RecordingObserver> recording_;
  ControllerParams params_;
  // [agents] the scenario's gait tag (AgentPlan::steering_gait_tag) while it
  // still pins the character; 0 once a host commands or sets its tags.
  std::vector<TagMask> steering_gait_masks_;
  ClipQuality clips_;

  // Per tick, sized once.
  std::vector<glm::vec3> desired_;  // [agents] the tick's desired velocities
  double wall_s_ = 0.0;  // the ticks' own time, summed
  std::optional<Recording> finished_;  // the recording, once write_html ended it
};

}  // namespace mmvk::crowd
