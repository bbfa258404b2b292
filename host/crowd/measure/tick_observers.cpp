#include "measure/tick_observers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>


namespace mmvk::crowd {

namespace {

constexpr float kNoPrediction = std::numeric_limits<float>::quiet_NaN();

// The trajectory error's horizon: the controller's trajectory offset nearest it.
constexpr float kErrorHorizon = 1.0f;

std::size_t horizon_index(const CrowdController& controller) {
  const auto offsets = controller.trajectory_offsets();
  std::size_t best = 0;
  for (std::size_t k = 1; k < offsets.size(); ++k) {
    if (std::abs(offsets[k] - kErrorHorizon) < std::abs(offsets[best] - kErrorHorizon)) best = k;
  }
  return best;
}

MotionMeterParams motion_params(const CrowdController& controller, const ControllerParams& params,
                                const ClipQuality& clips, double dt, double rate_hz, double fps) {
  MotionMeterParams p;
  p.legs = find_leg_joints(controller.animation());
  p.planted_height = clips.planted_height;
  p.dt = dt;
  // The spacing of the pose acceleration samples: the database's frame
  // interval in ticks (motion_meter.hpp).
  p.acceleration_step = std::uint32_t(std::clamp(std::lround(rate_hz / fps), 1L, 16L));
  // Three half-lives: the inertialization's blend has done 90% of its work.
  p.jump_window_s = 3.0 * params.inertialization_half_life;
  return p;
}

}  // namespace

void TickFigures::reserve(std::uint64_t ticks) { search_ms_.reserve(ticks), tick_ms_.reserve(ticks); }

void TickFigures::record(std::uint64_t tick, double tick_ms, double search_ms, std::span<const Match> matches,
                         std::uint64_t searches) {
  tick_ms_.push_back(tick_ms);
  search_ms_.push_back(search_ms);
  chosen_.add_u32(std::uint32_t(tick));
  chosen_.add_u32(std::uint32_t(matches.size()));
  for (const Match& m : matches) chosen_.add_u32(m.frame);
  searches_ += searches;
}

void TickFigures::summarize(CrowdSummary& s, double wall_seconds) const {
  s.searches = searches_;
  s.queries_per_tick = s.ticks ? double(searches_) / double(s.ticks) : 0.0;
  s.search_ms_p50 = percentile(search_ms_, 0.5);
  s.search_ms_p99 = percentile(search_ms_, 0.99);
  s.tick_ms_p50 = percentile(tick_ms_, 0.5);
  s.tick_ms_p99 = percentile(tick_ms_, 0.99);
  s.wall_seconds = wall_seconds;
  s.realtime_factor = wall_seconds > 0.0 ? s.seconds / wall_seconds : 0.0;
  s.chosen_frames_hash = chosen_.digest();
}

QualityObserver::QualityObserver(const CrowdController& controller, const ControllerParams& params,
                                 const ClipQuality& clips, double dt, double rate_hz, double fps)
    : horizon_index_(horizon_index(controller)),
      meter_(controller.size(), dt, controller.trajectory_offsets()[horizon_index_]),
      motion_(controller.size(), controller.animation().joint_count(),
              motion_params(controller, params, clips, dt, rate_hz, fps)),
      command_(controller.size(), dt),
      desired_xz_(2 * std::size_t{controller.size()}),
      root_xz_(2 * std::size_t{controller.size()}) {
  const auto feet = controller.animation().contact_joints;
  if (feet[0] >= 0 && feet[1] >= 0) toes_.resize(2 * std::size_t{controller.size()});
}

void QualityObserver::observe(const CrowdController& controller, const TickView& view) {
  // Where each character that searched this tick was predicted 1 s from
  // now, and where each is.
  const auto searched = controller.searched();
  const auto predicted = controller.predicted_positions();
  const auto roots = controller.root_positions();
  const std::size_t offsets = controller.trajectory_offsets().size();
  for (std::size_t b = 0; b < searched.size(); ++b) {
    const glm::vec3 p = predicted[b * offsets + horizon_index_];
    const bool fresh = searched[b] != SearchKind::None;
    desired_xz_[2 * b] = fresh ? p.x : kNoPrediction, desired_xz_[2 * b + 1] = fresh ? p.z : kNoPrediction;
    root_xz_[2 * b] = roots[b].x, root_xz_[2 * b + 1] = roots[b].z;
  }
  meter_.record_trajectory(desired_xz_, root_xz_);
  meter_.add_transitions(controller.last_tick().jumps);
  meter_.end_tick();
  // The pose as displayed (after foot IK) and as animated (before), the
  // latter the tick's own FK.
  motion_.record({view.world, controller.animated_world_positions(), controller.contacts(), controller.foot_locked(),
                  controller.ik_reach_clamped(), controller.jumped()});
  // The displayed toes, for the stillness of standing characters.
  const auto feet = controller.animation().contact_joints;
  const std::size_t joints = controller.animation().joint_count();
  for (std::size_t b = 0; b < toes_.size() / 2; ++b) {
    for (int side = 0; side < 2; ++side) toes_[2 * b + side] = view.world[b * joints + std::size_t(feet[side])];
  }
  command_.record(
      {view.desired, view.desired_yaw, roots, controller.root_yaws(), controller.root_corrections(), toes_});
}

void QualityObserver::summarize(CrowdSummary& s) const {
  s.trajectory_error_m_1s = meter_.trajectory_error_m_median();
  s.motion = motion_.figures();
  s.command = command_.figures();
  s.transitions_per_agent_s = meter_.transitions_per_agent_s();
}

RecordingObserver::RecordingObserver(const CrowdController& controller, const Scenario& scenario, std::string title,
                                     float dt, std::uint32_t ticks_per_sample,
                                     std::vector<std::uint32_t> detail_agents)
    : recorder_(controller, scenario, std::move(title), dt, ticks_per_sample, std::move(detail_agents)),
      frames_before_(controller.size()),
      kinds_before_(controller.size(), SearchKind::None) {}

void RecordingObserver::observe(const CrowdController& controller, const TickView& view) {
  recorder_.record_tick(view.tick, controller.applied_matches(), controller.applied_characters(), kinds_before_,
                        frames_before_, view.world);
  const auto kinds = controller.searched();
  recorder_.record_submitted(controller.submitted_characters(), controller.submitted_batch());
  std::copy(kinds.begin(), kinds.end(), kinds_before_.begin());
  const auto frames = controller.frames();
  std::copy(frames.begin(), frames.end(), frames_before_.begin());
}

}  // namespace mmvk::crowd
