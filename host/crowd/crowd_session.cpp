#include "crowd_session.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "clip_quality.hpp"
#include "crowd_limits.hpp"
#include "crowd_recorder.hpp"
#include "gait_plan.hpp"
#include "motion_meter.hpp"
#include "mmvk/trajectory.hpp"
#include "observed_search.hpp"
#include "quality_meter.hpp"
#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {

namespace {

using Clock = std::chrono::steady_clock;

// The controller settings `mmvk crowd` runs with (crowd_run.cpp says how
// they were measured): a jump must beat playing on by 2.5, and the root is
// pulled onto the simulated path with a 0.15 s half-life.
constexpr float kContinuingBias = -2.5f;
constexpr float kCorrectionHalfLife = 0.15f;
// The trajectory error's horizon (QualityMeter).
constexpr float kErrorHorizon[1] = {1.0f};

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
  return {};
}

// Tags by name, per agent, into the controller's query parameters.
Status apply_tags(const Scenario& scenario, const Database& database, std::span<QueryParams> params) {
  for (std::size_t a = 0; a < scenario.agents.size(); ++a) {
    const AgentPlan& plan = scenario.agents[a];
    const std::string where = scenario.source + ": agents[" + std::to_string(a) + "].";
    Result<TagMask> require = database.tag_mask(plan.require_tags);
    if (!require) return make_error(where + "require_tags: " + require.message());
    Result<TagMask> exclude = database.tag_mask(plan.exclude_tags);
    if (!exclude) return make_error(where + "exclude_tags: " + exclude.message());
    params[a].require_all = *require;
    params[a].exclude_any = *exclude;
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
  params.correction_half_life = kCorrectionHalfLife;
  params.foot_ik.enabled = options.foot_ik;
  MMVK_ASSIGN_OR_RETURN(CrowdController controller, CrowdController::create(database, agents, params));
  s->controller_.emplace(std::move(controller));
  CrowdController& c = *s->controller_;
  MMVK_TRY(apply_tags(s->scenario_, database, c.query_params()));
  for (std::uint32_t b = 0; b < agents; ++b) {
    const AgentPlan& plan = s->scenario_.agents[b];
    const float yaw = std::atan2(plan.goals[0][0] - plan.start[0], plan.goals[0][1] - plan.start[1]);
    MMVK_TRY(c.place(b, glm::vec3(plan.start[0], 0.0f, plan.start[1]), yaw));
  }
  MMVK_ASSIGN_OR_RETURN(s->search_, make_crowd_search(options.backend, options.device, database, agents, s->pool_, {}));
  s->observed_ = std::make_unique<ObservedSearch>(*s->search_.deferred, agents);
  s->steering_ = std::make_unique<Steering>(s->scenario_, s->speeds_);
  s->meter_ = std::make_unique<QualityMeter>(agents, s->dt_);

  const AnimationData& animation = c.animation();
  const std::size_t joints = animation.joint_count();
  // The clips first: their planted toe height is the crowd's floor.
  const ClipQuality clips = measure_clip_quality(database, s->pool_);
  s->clip_figures_ = clips.figures;
  s->planted_height_ = clips.planted_height;
  MotionMeterParams motion;
  motion.legs = find_leg_joints(animation);
  motion.planted_height = clips.planted_height;
  motion.dt = s->dt_;
  motion.acceleration_step = std::uint32_t(std::clamp(std::lround(options.rate_hz / database.fps()), 1L, 16L));
  motion.jump_window_s = 3.0 * params.inertialization_half_life;
  s->motion_ = std::make_unique<MotionMeter>(agents, joints, motion);
  if (options.record) {
    const auto per_sample = std::uint32_t(std::max(1.0, std::round(options.rate_hz / 10.0)));
    const std::string title = !options.title.empty()
                                  ? options.title
                                  : std::to_string(agents) + " agents \u00b7 " + std::string(s->search_.backend->name());
    s->recorder_ = std::make_unique<CrowdRecorder>(c, s->scenario_, title, float(s->dt_), per_sample);
  }

  s->x_.resize(agents), s->z_.resize(agents), s->vx_.resize(agents), s->vz_.resize(agents);
  s->desired_xz_.resize(2 * agents), s->root_xz_.resize(2 * agents);
  s->desired_.resize(agents), s->world_.resize(agents * joints), s->animated_.resize(agents * joints);
  s->frames_before_.resize(agents), s->kinds_before_.assign(agents, 0);
  s->searched_before_.reserve(agents), s->searched_now_.reserve(agents);
  return s;
}

Status CrowdSession::place(std::uint32_t b, float x, float z, float yaw, std::uint32_t frame) {
  return controller_->place(b, glm::vec3(x, 0.0f, z), yaw, frame);
}

Status CrowdSession::step() {
  const auto roots = controller_->root_positions();
  for (std::uint32_t b = 0; b < agents_; ++b) x_[b] = roots[b].x, z_[b] = roots[b].z;
  steering_->update(x_, z_, vx_, vz_);
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
  for (std::uint32_t b = 0; b < agents_; ++b) desired_[b] = glm::vec3(desired_velocity[b].x, 0.0f, desired_velocity[b].z);
  return tick(desired_, desired_yaw);
}

// The loop body of run_crowd (crowd_run.cpp), for one tick.
Status CrowdSession::tick(std::span<const glm::vec3> desired, std::span<const float> desired_yaw) {
  CrowdController& c = *controller_;
  const auto tick_start = Clock::now();
  observed_->begin_tick();
  MMVK_TRY(c.tick(float(dt_), CrowdInput{desired, desired_yaw}, *observed_, pool_));
  const double tick_s = std::chrono::duration<double>(Clock::now() - tick_start).count();
  wall_s_ += tick_s;
  tick_ms_.push_back(tick_s * 1e3);
  search_ms_.push_back(observed_->blocked_seconds() * 1e3);

  const auto matches = observed_->collected_matches();
  chosen_.add_u32(std::uint32_t(ticks_));
  chosen_.add_u32(std::uint32_t(matches.size()));
  for (const Match& m : matches) chosen_.add_u32(m.frame);
  searches_ += c.last_tick().searches;

  // Where the controller wants each character 1 s from now, and where it is.
  const auto sim = c.simulation();
  const auto roots = c.root_positions();
  glm::vec3 horizon_pos[1];
  float horizon_yaw[1];
  const SpringParams& spring = c.params().spring;
  for (std::uint32_t b = 0; b < agents_; ++b) {
    const float yaw = desired_yaw.empty() ? yaw_of_velocity(desired[b], sim[b].yaw) : desired_yaw[b];
    predict_trajectory(sim[b], desired[b], yaw, spring, kErrorHorizon, horizon_pos, horizon_yaw);
    desired_xz_[2 * b] = horizon_pos[0].x, desired_xz_[2 * b + 1] = horizon_pos[0].z;
    root_xz_[2 * b] = roots[b].x, root_xz_[2 * b + 1] = roots[b].z;
  }
  meter_->record_trajectory(desired_xz_, root_xz_);
  meter_->add_transitions(c.last_tick().jumps);
  meter_->end_tick();
  c.world_positions(world_, pool_);
  c.animated_world_positions(animated_, pool_);
  motion_->record({world_, animated_, c.contacts(), c.foot_locked(), c.ik_reach_clamped(), c.jumped()});

  if (recorder_ && !html_written_) {
    recorder_->record_tick(ticks_, matches, searched_before_, kinds_before_, frames_before_, world_);
  }
  searched_now_.clear();
  const auto kinds = c.searched();
  for (std::uint32_t b = 0; b < agents_; ++b) {
    if (kinds[b] != 0) searched_now_.push_back(b);
  }
  searched_before_.swap(searched_now_);
  std::copy(kinds.begin(), kinds.end(), kinds_before_.begin());
  const auto frames = c.frames();
  std::copy(frames.begin(), frames.end(), frames_before_.begin());
  ++ticks_;
  return {};
}

CrowdSummary CrowdSession::summary() const {
  const CrowdController& c = *controller_;
  CrowdSummary s;
  s.agents = agents_;
  s.ticks = ticks_;
  s.seconds = double(ticks_) * dt_;
  s.rate_hz = options_.rate_hz;
  s.search_interval_s = options_.search_interval_s;
  s.seed = options_.seed;
  s.scenario = scenario_.source;
  s.database_frames = database_.frame_count();
  s.walk_mps = speeds_.walk_mps;
  s.run_mps = speeds_.has_run ? speeds_.run_mps : std::nan("");
  s.runners = count_runners(scenario_);
  if (!speeds_.has_run) s.notes.push_back("run_mps is null: the data has no run (" + speeds_.no_run_reason + ")");
  s.backend = std::string(search_.backend->name());
  s.device = search_.device;
  s.searches = searches_;
  s.forced_searches = c.totals().forced;
  s.no_candidate = c.totals().no_candidate;
  s.queries_per_tick = ticks_ ? double(searches_) / double(ticks_) : 0.0;
  s.search_ms_p50 = percentile(search_ms_, 0.5);
  s.search_ms_p99 = percentile(search_ms_, 0.99);
  s.tick_ms_p50 = percentile(tick_ms_, 0.5);
  s.tick_ms_p99 = percentile(tick_ms_, 0.99);
  s.wall_seconds = wall_s_;
  s.realtime_factor = wall_s_ > 0.0 ? s.seconds / wall_s_ : 0.0;
  s.trajectory_error_m_1s = meter_->trajectory_error_m_median();
  s.foot_ik = options_.foot_ik;
  s.motion = motion_->figures();
  s.clips = clip_figures_;
  s.planted_height_m = planted_height_;
  s.transitions_per_agent_s = meter_->transitions_per_agent_s();
  s.goals_reached = steering_->goals_reached();
  s.chosen_frames_hash = chosen_.digest();
  return s;
}

Result<std::size_t> CrowdSession::write_html(const std::filesystem::path& path) {
  if (!recorder_) return make_error("write_html: the crowd was made without record=True, so nothing was recorded");
  if (html_written_) return make_error("write_html: the recording was already written (it ends at the first page)");
  html_written_ = true;
  Recording recording = recorder_->finish(pool_);
  return write_viewer_html(path, recording);
}

}  // namespace mmvk::crowd
