#include "measure/command_meter.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace mmvk::crowd {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;
// A held command: the desired velocity within this of it (m/s); moving from
// this speed (m/s); settled after this long (seconds).
constexpr double kHoldTolerance = 0.1;
constexpr double kMovingSpeed = 0.2;
constexpr double kSettleSeconds = 1.0;
// A stand is steady later: the issue gives a stop 1.2 s to come to rest.
constexpr double kStopSettleSeconds = 1.2;

double horizontal(const glm::vec3& v) { return std::hypot(double(v.x), double(v.z)); }

}  // namespace

CommandMeter::CommandMeter(std::size_t agents, double dt)
    : dt_(dt),
      settle_ticks_(std::max<std::uint64_t>(1, std::uint64_t(std::llround(kSettleSeconds / dt)))),
      stop_settle_ticks_(std::max<std::uint64_t>(1, std::uint64_t(std::llround(kStopSettleSeconds / dt)))),
      agents_(agents),
      glide_(0.1, 20000),
      played_error_(0.001, 5000),
      shown_error_(0.001, 5000),
      heading_error_(0.1, 1800) {}

void CommandMeter::record(const Tick& tick) {
  for (std::size_t b = 0; b < agents_.size(); ++b) {
    Agent& a = agents_[b];
    const glm::vec3 desired = tick.desired[b];
    if (horizontal(desired - a.held) > kHoldTolerance) {
      a.held = desired;
      a.held_ticks = 0;
      a.window_ticks = 0, a.played_m = a.shown_m = a.commanded_m = 0.0;
    }
    ++a.held_ticks;
    ++agent_ticks_;
    const glm::vec3 step = tick.roots[b] - a.last_root;
    const bool counted = a.seen && horizontal(step) <= kTeleport;
    const bool steady = a.held_ticks > settle_ticks_;
    if (counted && a.held_ticks > stop_settle_ticks_ && horizontal(a.held) < kStandCommand) {
      record_standing(a, tick, b, horizontal(step));
    }
    a.last_root = tick.roots[b];
    if (!tick.toes.empty()) a.last_toes[0] = tick.toes[2 * b], a.last_toes[1] = tick.toes[2 * b + 1];
    a.seen = true;
    if (!counted) continue;
    const double shown = horizontal(step);
    const double correction = horizontal(tick.corrections[b]);
    // The animation's own step: the shown step without the correction.
    const double played = horizontal(step - tick.corrections[b]);
    travel_m_ += shown;
    correction_m_ += correction;
    animation_m_ += played;
    glide_.add(100.0 * correction / dt_);
    if (steady && horizontal(a.held) >= kMovingSpeed) record_steady(a, tick, b, shown, played);
  }
}

void CommandMeter::record_standing(const Agent& a, const Tick& tick, std::size_t b, double shown) {
  if (tick.toes.empty()) return;
  ++steady_standing_ticks_;
  const double still = kStillSpeed * dt_;  // metres per tick
  const bool toes_still = glm::length(tick.toes[2 * b] - a.last_toes[0]) < still &&
                          glm::length(tick.toes[2 * b + 1] - a.last_toes[1]) < still;
  still_ticks_ += shown < still && toes_still ? 1 : 0;
}

void CommandMeter::record_steady(Agent& a, const Tick& tick, std::size_t b, double shown, double played) {
  ++steady_moving_ticks_;
  const glm::vec3 desired = tick.desired[b];
  const double desired_yaw =
      tick.desired_yaw.empty() ? std::atan2(double(desired.x), double(desired.z)) : double(tick.desired_yaw[b]);
  heading_error_.add(std::abs(std::remainder(double(tick.root_yaws[b]) - desired_yaw, 2.0 * kPi)) * kRadToDeg);
  a.played_m += played;
  a.shown_m += shown;
  a.commanded_m += horizontal(desired) * dt_;
  if (++a.window_ticks < settle_ticks_) return;
  const double played_ratio = a.played_m / a.commanded_m;
  played_error_.add(std::abs(played_ratio - 1.0));
  if (std::abs(played_ratio - 1.0) > kMissedSpeed) {
    CommandFigures::Missed& missed = played_ratio > 1.0 ? too_fast_ : too_slow_;
    const double commanded = a.commanded_m / (double(a.window_ticks) * dt_);
    ++missed.windows;
    missed.min_mps = missed.windows == 1 ? commanded : std::min(missed.min_mps, commanded);
    missed.max_mps = missed.windows == 1 ? commanded : std::max(missed.max_mps, commanded);
  }
  shown_error_.add(std::abs(a.shown_m / a.commanded_m - 1.0));
  a.window_ticks = 0, a.played_m = a.shown_m = a.commanded_m = 0.0;
}

CommandFigures CommandMeter::figures() const {
  CommandFigures f;
  if (glide_.count()) {
    f.glide_cm_s_mean = glide_.mean();
    f.glide_cm_s_median = glide_.quantile(0.5);
    f.glide_cm_s_p95 = glide_.quantile(0.95);
  }
  if (travel_m_ > 0.0) {
    f.glide_share_of_travel = correction_m_ / travel_m_;
    f.animation_share_of_travel = animation_m_ / travel_m_;
  }
  if (agent_ticks_) f.steady_moving_fraction = double(steady_moving_ticks_) / double(agent_ticks_);
  if (agent_ticks_ && steady_standing_ticks_) {
    f.steady_standing_fraction = double(steady_standing_ticks_) / double(agent_ticks_);
    f.standing_still_share = double(still_ticks_) / double(steady_standing_ticks_);
  }
  f.played_speed_error_median = played_error_.quantile(0.5);
  f.played_speed_error_p95 = played_error_.quantile(0.95);
  f.shown_speed_error_median = shown_error_.quantile(0.5);
  f.shown_speed_error_p95 = shown_error_.quantile(0.95);
  f.heading_error_deg_median = heading_error_.quantile(0.5);
  f.heading_error_deg_p95 = heading_error_.quantile(0.95);
  f.too_fast = too_fast_;
  f.too_slow = too_slow_;
  f.windows = played_error_.count();
  return f;
}

}  // namespace mmvk::crowd
