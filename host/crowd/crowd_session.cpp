#include "crowd_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "clip_quality.hpp"
#include "crowd_defaults.hpp"
#include "crowd_limits.hpp"
#include "mmvk/number_text.hpp"
#include "gait_plan.hpp"
#include "observed_search.hpp"
#include "observed_tick.hpp"
#include "run_summary.hpp"
#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {

namespace {

using Clock = std::chrono::steady_clock;

Status check_options(const CrowdSessionOptions& o) {
  if (!o.scenario && o.agents == 0) return make_error("agents must be at least 1");
  if (!o.scenario && o.agents > kMaxAgents) {
    return make_error("agents: " + std::to_string(o.agents) + " is more than the crowd's limit of " +
                      std::to_string(kMaxAgents));
  }
  if (!(o.rate_hz > 0.0) || !std::isfinite(o.rate_hz)) return make_error("rate must be a positive number (Hz)");
  if (!(o.search_interval_s > 0.0) || !std::isfinite(o.search_interval_s)) {
    return make_error("search_interval must be a positive number (seconds)");
  }
  if (o.correction_half_life && !(std::isfinite(*o.correction_half_life) && *o.correction_half_life > 0.0f)) {
    return make_error("correction_half_life must be a positive number (seconds)");
  }
  return {};
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
  MMVK_TRY(check_options(options));
  if (!database.animation()) return missing_animation_error("mmvk.Crowd");
  MMVK_ASSIGN_OR_RETURN(GaitSpeeds speeds, measure_gait_speeds(database));
  Scenario scenario;
  if (options.scenario) {
    scenario = *options.scenario;
  } else {
    RandomScenarioOptions random;
    random.agents = options.agents;
    random.seed = options.seed;
    if (!speeds.has_run) random.run_fraction = 0.0f;  // data without a run gets no runners
    scenario = make_random_scenario(random);
  }
  MMVK_TRY(resolve_gaits(scenario, speeds));
  std::unique_ptr<CrowdSession> s(new CrowdSession(database, std::move(scenario), std::move(speeds), options));
  const std::uint32_t agents = s->agents_;

  ControllerParams params;
  params.search_interval = float(options.search_interval_s);
  params.continuing_bias = kContinuingBias;
  params.correction_half_life = options.correction_half_life.value_or(kCorrectionHalfLife);
  params.foot_ik.enabled = options.foot_ik;
  MMVK_ASSIGN_OR_RETURN(CrowdController controller, CrowdController::create(database, agents, params));
  s->controller_.emplace(std::move(controller));
  CrowdController& c = *s->controller_;
  MMVK_TRY(apply_plan_tags(s->scenario_, database, c.query_params()));
  for (std::uint32_t b = 0; b < agents; ++b) {
    const AgentPlan& plan = s->scenario_.agents[b];
    const float yaw = std::atan2(plan.goals[0][0] - plan.start[0], plan.goals[0][1] - plan.start[1]);
    MMVK_TRY(c.place(b, glm::vec3(plan.start[0], 0.0f, plan.start[1]), yaw));
  }
  MMVK_ASSIGN_OR_RETURN(s->search_, make_crowd_search(options.backend, options.device, database, agents, s->pool_, {}));
  s->observed_ = std::make_unique<ObservedSearch>(*s->search_.deferred, agents);
  s->steering_ = std::make_unique<Steering>(s->scenario_, s->speeds_);
  // The clips first: their planted toe height is the crowd's floor.
  const ClipQuality clips = measure_clip_quality(database, s->pool_);
  s->clips_ = clips;
  s->params_ = params;
  s->quality_ = std::make_unique<QualityObserver>(c, params, clips, s->dt_, options.rate_hz, database.fps());
  if (options.record) {
    const auto per_sample = std::uint32_t(std::max(1.0, std::round(options.rate_hz / 10.0)));
    const std::string title = !options.title.empty()
                                  ? options.title
                                  : std::to_string(agents) + " agents \u00b7 " + std::string(s->search_.backend->name());
    s->recording_ = std::make_unique<RecordingObserver>(c, s->scenario_, title, float(s->dt_), per_sample);
  }

  s->x_.resize(agents), s->z_.resize(agents), s->vx_.resize(agents), s->vz_.resize(agents);
  s->desired_.resize(agents), s->world_.resize(std::size_t{agents} * c.animation().joint_count());
  return s;
}

Status CrowdSession::place(std::uint32_t b, float x, float z, float yaw, std::uint32_t frame) {
  return controller_->place(b, glm::vec3(x, 0.0f, z), yaw, frame);
}

Status CrowdSession::step() {
  const auto roots = controller_->root_positions();
  for (std::uint32_t b = 0; b < agents_; ++b) x_[b] = roots[b].x, z_[b] = roots[b].z;
  steering_->update(x_, z_, vx_, vz_, &pool_);
  for (std::uint32_t b = 0; b < agents_; ++b) desired_[b] = glm::vec3(vx_[b], 0.0f, vz_[b]);
  return tick(desired_, {});
}

Status CrowdSession::step(std::span<const glm::vec3> desired_velocity, std::span<const float> desired_yaw) {
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
  return tick(desired_, desired_yaw);
}

// The loop body of run_crowd (crowd_run.cpp), for one tick.
Status CrowdSession::tick(std::span<const glm::vec3> desired, std::span<const float> desired_yaw) {
  // The recording ends at the first page written.
  RecordingObserver* recording = finished_ ? nullptr : recording_.get();
  MMVK_ASSIGN_OR_RETURN(const double tick_ms,
                        observed_tick(*controller_, *observed_, pool_, ticks_, float(dt_),
                                      CrowdInput{desired, desired_yaw}, Clock::now(), world_,
                                      {figures_, *quality_, recording}));
  wall_s_ += tick_ms / 1e3;
  ++ticks_;
  return {};
}

CrowdSummary CrowdSession::summary() const {
  CrowdSummary s = summarize_run({database_, scenario_, speeds_, search_, *controller_, params_, *quality_, clips_,
                                  *steering_, ticks_, options_.rate_hz, options_.search_interval_s, options_.seed,
                                  options_.foot_ik});
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
  if (!finished_) finished_ = recording_->finish(pool_);
  return write_viewer_html(path, *finished_);
}

}  // namespace mmvk::crowd
