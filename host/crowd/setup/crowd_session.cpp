#include "setup/crowd_session.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "measure/clip_quality.hpp"
#include "setup/crowd_defaults.hpp"
#include "setup/crowd_limits.hpp"
#include "setup/data_settings.hpp"
#include "mmvk/common/number_text.hpp"
#include "steering/gait_plan.hpp"
#include "measure/observed_tick.hpp"
#include "measure/run_summary.hpp"
#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {

namespace {

using Clock = std::chrono::steady_clock;

std::string data_name(const CrowdSessionOptions& o) {
  return o.data_source.empty() ? std::string("the database") : o.data_source;
}

// The motion checked for a crowd: it has animation and walks.
Result<GaitSpeeds> check_motion(const Database& database, const CrowdSessionOptions& o) {
  const std::string caller = o.names == SettingNames::Flags ? "mmvk crowd" : "mmvk.Crowd";
  if (!database.animation()) return make_error(data_name(o) + ": " + missing_animation_error(caller, database.no_animation_reason()).message);
  Result<GaitSpeeds> speeds = measure_gait_speeds(database);
  if (!speeds) return make_error(data_name(o) + ": " + speeds.message());
  return speeds;
}

// The scenario given, or the random one of the settings, its gaits
// resolved, once the run is known to fit in memory.
Result<Scenario> plan_scenario(const Database& database, const CrowdSessionOptions& o, const GaitSpeeds& speeds) {
  RunOutputs outputs = o.outputs;
  outputs.html = outputs.html || o.record;
  if (o.scenario && o.agents && *o.agents != o.scenario->agents.size()) {
    return make_error(o.scenario->source + ": defines " + std::to_string(o.scenario->agents.size()) +
                      " agents, but " + setting_name(o.names, "agents") + " asks for " + std::to_string(*o.agents) +
                      " (leave " + setting_name(o.names, "agents") + " out with a scenario)");
  }
  // The detailed characters within the crowd, before the memory estimate counts them.
  const std::uint64_t agents = o.scenario ? o.scenario->agents.size() : o.agents.value_or(kDefaultAgents);
  if (o.record) {
    MMVK_TRY(resolve_detail_agents(o.detail_agents, agents, setting_name(o.names, "detail-agents")).status());
  }
  Scenario scenario;
  if (o.scenario) {
    // Its agents' waits are its own: one setting that overrode some of them
    // would leave a reader of the file guessing which.
    if (o.wait_at_goals_s != 0.0) {
      return make_error(setting_name(o.names, "wait-at-goals") + " sets the random scenario's wait; " +
                        o.scenario->source + " sets its own (\"wait_s\", per agent or for all)");
    }
    MMVK_TRY(check_crowd_memory(o, outputs, database, &*o.scenario, o.names));
    scenario = *o.scenario;
  } else {
    MMVK_TRY(check_crowd_memory(o, outputs, database, nullptr, o.names));
    RandomScenarioOptions random;
    random.agents = std::uint32_t(agents);
    random.seed = o.seed;
    random.wait_s = float(o.wait_at_goals_s);
    if (!speeds.has_run) random.run_fraction = 0.0f;  // data without a run gets no runners
    scenario = make_random_scenario(random);
  }
  // The crowd's controller chooses each search's gait where the data
  // measured them (ControllerParams::choose_gait is on).
  MMVK_TRY(resolve_gaits(scenario, speeds));
  return scenario;
}

// "1000 agents · CMU 16 walks and runs · vulkan-brute-force on llvmpipe".
std::string page_title(const CrowdSessionOptions& o, std::uint32_t agents, const CrowdSearch& search) {
  if (!o.title.empty()) return o.title;
  const std::string device = search.device.substr(0, search.device.find(" ("));
  return std::to_string(agents) + " agents \u00b7 " + (o.data_label.empty() ? "" : o.data_label + " \u00b7 ") +
         std::string(search.backend->name()) + " on " + device;
}

}  // namespace

CrowdSession::CrowdSession(const Database& database, Scenario scenario, GaitSpeeds speeds,
                           const CrowdSessionOptions& options)
    : database_(database),
      scenario_(std::move(scenario)),
      speeds_(std::move(speeds)),
      options_(options),
      agents_(std::uint32_t(scenario_.agents.size())),
      dt_(1.0 / options.rate_hz),
      pool_(0) {}

CrowdSession::~CrowdSession() = default;

Result<std::unique_ptr<CrowdSession>> CrowdSession::create(const Database& database,
                                                           const CrowdSessionOptions& options) {
  MMVK_TRY(validate(options, options.names));
  MMVK_ASSIGN_OR_RETURN(GaitSpeeds speeds, check_motion(database, options));
  MMVK_ASSIGN_OR_RETURN(const DataSettings data, data_settings(database, data_name(options)));
  const ControllerParams params = controller_params(options, data);
  MMVK_TRY(check_query_settings(options, params, database, options.names));
  MMVK_ASSIGN_OR_RETURN(Scenario scenario, plan_scenario(database, options, speeds));
  std::unique_ptr<CrowdSession> s(new CrowdSession(database, std::move(scenario), std::move(speeds), options));
  s->options_.scenario.reset();  // the session keeps its own copy, scenario_
  MMVK_TRY(s->set_up(params));
  return s;
}

// The controller, the search and the observers, in the order `mmvk crowd`
// has always made them (the random draws and the chosen frames depend on it).
Status CrowdSession::set_up(const ControllerParams& params) {
  const CrowdSessionOptions& o = options_;
  Result<CrowdController> created = CrowdController::create(database_, agents_, params);
  if (!created) return make_error(data_name(o) + ": " + created.message());
  controller_.emplace(std::move(created.value()));
  CrowdController& c = *controller_;
  MMVK_TRY(apply_plan_tags(scenario_, database_, c.query_params()));
  // The gait tags added for the crowd's own steering, lifted where a host
  // commands the gait and the controller can choose it.
  steering_gait_masks_.assign(agents_, 0);
  if (database_.gait_bands() != nullptr && params.choose_gait) {
    for (std::uint32_t b = 0; b < agents_; ++b) {
      const std::string& tag = scenario_.agents[b].steering_gait_tag;
      if (tag.empty()) continue;
      MMVK_ASSIGN_OR_RETURN(steering_gait_masks_[b], database_.tag_mask(std::span<const std::string>(&tag, 1)));
    }
  }
  MMVK_TRY(apply_query_settings(o, database_, o.names, c.query_params()));
  for (std::uint32_t b = 0; b < agents_; ++b) {
    const AgentPlan& plan = scenario_.agents[b];
    const float yaw = std::atan2(plan.goals[0][0] - plan.start[0], plan.goals[0][1] - plan.start[1]);
    MMVK_TRY(c.place(b, glm::vec3(plan.start[0], 0.0f, plan.start[1]), yaw));
  }
  MMVK_ASSIGN_OR_RETURN(search_, make_crowd_search(o.backend, o.device, database_, agents_, pool_, o.cache_dir));
  steering_ = std::make_unique<Steering>(scenario_, speeds_);
  // The clips first: their planted toe height is the crowd's floor.
  clips_ = measure_clip_quality(database_, pool_);
  params_ = params;
  quality_ = std::make_unique<QualityObserver>(c, params, clips_, dt_, o.rate_hz, database_.fps());
  if (o.record) {
    // One sample every tenth of a second.
    const auto per_sample = std::uint32_t(std::max(1.0, std::round(o.rate_hz / 10.0)));
    MMVK_ASSIGN_OR_RETURN(std::vector<std::uint32_t> detail,
                          resolve_detail_agents(o.detail_agents, agents_, setting_name(o.names, "detail-agents")));
    recording_ = std::make_unique<RecordingObserver>(c, scenario_, page_title(o, agents_, search_), float(dt_),
                                                     per_sample, std::move(detail));
  }
  desired_.resize(agents_);
  return {};
}

Status CrowdSession::place(std::uint32_t b, float x, float z, float yaw, std::uint32_t frame) {
  return controller_->place(b, glm::vec3(x, 0.0f, z), yaw, frame);
}

Status CrowdSession::set_tags(std::span<const std::uint64_t> agents, std::span<const std::string> require,
                              std::span<const std::string> exclude) {
  for (const std::uint64_t b : agents) {
    if (b >= agents_) {
      return make_error("agents: " + std::to_string(b) + " is not a character of this crowd (0 to " +
                        std::to_string(agents_ - 1) + ")");
    }
  }
  Result<TagMask> required = database_.tag_mask(require);
  if (!required.ok()) return make_error("require: " + required.message());
  Result<TagMask> excluded = database_.tag_mask(exclude);
  if (!excluded.ok()) return make_error("exclude: " + excluded.message());
  if ((*required & *excluded) != 0) return make_error("require, exclude: a tag is both required and excluded");
  const std::span<QueryParams> params = controller_->query_params();
  for (const std::uint64_t b : agents) {
    params[b].require_all = *required;
    params[b].exclude_any = *excluded;
    steering_gait_masks_[b] = 0;  // the host's tags are the host's
  }
  return {};
}

Status CrowdSession::step() {
  // The tick's time counts the steering too.
  const auto tick_start = Clock::now();
  steering_->update(controller_->root_positions(), desired_, float(dt_), &pool_);
  return tick(desired_, {}, tick_start);
}

Status CrowdSession::step(std::span<const glm::vec3> desired_velocity, std::span<const float> desired_yaw) {
  const auto tick_start = Clock::now();
  if (desired_velocity.size() != agents_) {
    return make_error("desired_velocity: " + std::to_string(desired_velocity.size()) + " rows for " +
                      std::to_string(agents_) + " agents");
  }
  if (!desired_yaw.empty() && desired_yaw.size() != agents_) {
    return make_error("desired_facing: " + std::to_string(desired_yaw.size()) + " values for " +
                      std::to_string(agents_) + " agents");
  }
  for (std::uint32_t b = 0; b < agents_; ++b) {
    // A speed no motion has (1e30 m/s) overflowed the search's costs later,
    // in a message that named neither the argument nor the row.
    const float speed = std::hypot(desired_velocity[b].x, desired_velocity[b].z);
    if (speed > kMaxDesiredSpeed) {
      return make_error("desired_velocity[" + std::to_string(b) + "]: " + number_text(speed) + " m/s is over " +
                        number_text(kMaxDesiredSpeed) + " m/s");
    }
    desired_[b] = glm::vec3(desired_velocity[b].x, 0.0f, desired_velocity[b].z);
  }
  // The host commands the speed: the controller chooses the gait from it,
  // free of the walk or run tag the scenario's plan added for the crowd's
  // own steering (a walker told to run runs).
  const std::span<QueryParams> params = controller_->query_params();
  for (std::uint32_t b = 0; b < agents_; ++b) {
    params[b].require_all &= ~steering_gait_masks_[b];
    steering_gait_masks_[b] = 0;
  }
  return tick(desired_, desired_yaw, tick_start);
}

Status CrowdSession::tick(std::span<const glm::vec3> desired, std::span<const float> desired_yaw,
                          Clock::time_point tick_start) {
  // The recording ends at the first page written.
  RecordingObserver* recording = finished_ ? nullptr : recording_.get();
  if (ticks_ == 0) figures_.reserve(tick_count(options_));
  MMVK_ASSIGN_OR_RETURN(const double tick_ms,
                        observed_tick(*controller_, *search_.deferred, pool_, ticks_, float(dt_),
                                      CrowdInput{desired, desired_yaw}, tick_start, {figures_, *quality_, recording}));
  wall_s_ += tick_ms / 1e3;
  ++ticks_;
  return {};
}

CrowdSummary CrowdSession::summary() const {
  CrowdSummary s = summarize_run({database_, scenario_, speeds_, search_, *controller_, params_, *quality_, clips_,
                                  *steering_, ticks_, options_.rate_hz, options_.search_interval_s, options_.seed,
                                  options_.foot_ik, options_.speed_from_animation});
  figures_.summarize(s, wall_s_);
  return s;
}

Result<std::size_t> CrowdSession::write_html(const std::filesystem::path& path) {
  if (!recording_) return make_error("write_html: the crowd was made without record=True, so nothing was recorded");
  // Refused before the recording ends: a page of no ticks shows nothing,
  // and the steps that follow are still recorded.
  if (ticks_ == 0) return make_error("write_html: nothing was recorded yet (step the crowd first)");
  // The recording ends at the first page, but is kept: a write that fails
  // (a missing folder, a full disk) can be retried with the same run.
  if (!finished_) {
    MMVK_ASSIGN_OR_RETURN(Recording finished, recording_->finish(pool_));
    finished_ = std::move(finished);
  }
  return write_viewer_html(path, *finished_);
}

}  // namespace mmvk::crowd
