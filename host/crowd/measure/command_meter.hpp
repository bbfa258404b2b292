// How closely the characters do what their steering commands, and how much
// of their travel the root correction supplies rather than the animation
// (the glide), tick by tick with memory independent of the run's length
// (histograms and sums). The same for the crowd's own steering and for a
// host's (CrowdSession::step with desired velocities): both reach the
// controller as a desired velocity and facing per character.
//
// Per character and tick of dt seconds:
//   - glide: the correction's speed, |CrowdController::root_corrections()| /
//     dt, over every tick (mean, median and p95, cm/s), and its share of the
//     travel: the sum of the corrections' lengths over the sum of the shown
//     root's step lengths. The animation's share is the same sum of its own
//     root steps (the shown step less the correction) over the travel.
//   - steady: a character is steady once its desired velocity has stayed
//     within 0.1 m/s of one value for 1 s (the time the issue gives a start
//     or turn to settle), and moving when that value is at least 0.2 m/s.
//   - speed error: over each second of steady moving ticks, the animation's
//     own root speed (played) and the shown root's (path length / time)
//     against the commanded speed, as |speed / commanded - 1|: median and
//     p95 over those windows.
//   - heading error: on steady moving ticks, the shown root's yaw against the
//     desired yaw (or, without one, the desired velocity's direction),
//     degrees: median and p95.
//   - still while told to stand: on steady standing ticks (a command under
//     kStandCommand held for 1.2 s, the time the issue gives a stop), the
//     share whose shown root and both
//     toes each moved under kStillSpeed (the 5 cm/s).
//   - missed speeds: the windows whose played speed is more than 20% off
//     the command, too fast or too slow, with the commanded speeds they
//     span: the speeds the data cannot play within the play-rate bounds.
// A step longer than kTeleport (a character placed elsewhere between ticks)
// is not travel and is left out.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "measure/histogram.hpp"

namespace mmvk::crowd {

// NaN: not measured (no steady moving ticks, no travel).
struct CommandFigures {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double glide_cm_s_mean = kNone, glide_cm_s_median = kNone, glide_cm_s_p95 = kNone;
  double glide_share_of_travel = kNone;
  double animation_share_of_travel = kNone;
  double steady_moving_fraction = kNone;  // of agent-ticks
  double steady_standing_fraction = kNone;  // of agent-ticks
  double standing_still_share = kNone;      // of the steady standing ticks
  double played_speed_error_median = kNone, played_speed_error_p95 = kNone;  // fractions of the command
  double shown_speed_error_median = kNone, shown_speed_error_p95 = kNone;
  double heading_error_deg_median = kNone, heading_error_deg_p95 = kNone;
  // The speeds the data lacks: of the held windows, those whose played
  // speed was more than kMissedSpeed above (too_fast) or below (too_slow)
  // the command, their count and the range of commanded speeds (m/s).
  struct Missed {
    std::uint64_t windows = 0;
    double min_mps = kNone, max_mps = kNone;
  };
  Missed too_fast, too_slow;
  std::uint64_t windows = 0;  // held windows in all
};

class CommandMeter {
 public:
  static constexpr double kTeleport = 5.0;  // metres in one tick
  static constexpr double kMissedSpeed = 0.2;  // fraction of the command
  static constexpr double kStandCommand = 0.05;  // m/s: a command under it asks the character to stand
  static constexpr double kStillSpeed = 0.05;    // m/s

  CommandMeter(std::size_t agents, double dt);

  // One tick, [agents] each: the desired velocity (world m/s) and yaw (or
  // empty), the shown root and its yaw, this tick's root correction (world
  // metres), and the displayed toes (left, right; [agents x 2] world, or
  // empty: no stillness measured).
  struct Tick {
    std::span<const glm::vec3> desired;
    std::span<const float> desired_yaw;
    std::span<const glm::vec3> roots;
    std::span<const float> root_yaws;
    std::span<const glm::vec3> corrections;
    std::span<const glm::vec3> toes = {};
  };
  void record(const Tick& tick);

  CommandFigures figures() const;

 private:
  // Per character: the command it holds, and the window being summed.
  struct Agent {
    glm::vec3 held{0.0f};
    std::uint64_t held_ticks = 0;
    glm::vec3 last_root{0.0f};
    glm::vec3 last_toes[2]{glm::vec3(0.0f), glm::vec3(0.0f)};
    bool seen = false;
    std::uint64_t window_ticks = 0;
    double played_m = 0.0, shown_m = 0.0, commanded_m = 0.0;
  };
  void record_steady(Agent& a, const Tick& tick, std::size_t b, double shown, double played);
  // A steady standing tick of b: still or not.
  void record_standing(const Agent& a, const Tick& tick, std::size_t b, double shown);

  double dt_;
  std::uint64_t settle_ticks_, stop_settle_ticks_;
  std::vector<Agent> agents_;
  std::uint64_t agent_ticks_ = 0, steady_moving_ticks_ = 0, steady_standing_ticks_ = 0, still_ticks_ = 0;
  double travel_m_ = 0.0, correction_m_ = 0.0, animation_m_ = 0.0;
  Histogram glide_;           // cm/s
  Histogram played_error_, shown_error_;  // fractions
  Histogram heading_error_;   // degrees
  CommandFigures::Missed too_fast_, too_slow_;
};

}  // namespace mmvk::crowd
