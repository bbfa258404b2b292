// The motion figures of what a character shows, measured from world joint
// positions tick by tick with memory independent of the run's length
// (histograms and sums). The crowd feeds it every character's displayed
// pose; clip_quality.hpp feeds it the database's own clips, so the two sets
// of figures are the same measurement.
//
// Per stream (a character, or a clip) and tick of dt seconds:
//   - foot sliding: the horizontal speed of a foot's point on the ground
//     between two ticks where the foot is flagged in contact (FootContact
//     planted bits) at both, mean in cm/s; the same on the pose before foot
//     IK when it is given. The point is the contact joint (the toe), or the
//     ankle while the frame says only the heel touches (heel bit without the
//     toe bit): a foot rolling onto its toe after a heel strike moves its
//     toe down and forward without sliding, and foot IK holds the heel then.
//   - foot locks: of the foot-ticks flagged in contact, the fraction locked;
//     of all foot-ticks, the fraction whose leg was soft-clamped by the IK.
//   - knee angular speed: the knee's flexion angle is the angle between the
//     thigh (upper leg joint to knee) and the shin (knee to ankle), from the
//     joint positions, so it measures what is drawn whichever joint rotates;
//     its change per tick / dt, p99 over every knee-tick, deg/s. A knee that
//     pops (an IK snapping near full extension, a blend that flips) shows
//     here first.
//   - foot height in contact: the contact joint's height above the floor
//     (y = 0 world) minus its height when planted (planted_height, measured
//     on the clips: the joint sits above the sole), over the foot-ticks
//     flagged in contact: signed mean (sinking < 0 < floating) and the p95 of
//     its magnitude, cm.
//   - pose acceleration: per stream and tick, the mean over joints of
//     |p(t) - 2 p(t - k) + p(t - 2k)| / (k dt)^2, m/s^2, with k =
//     acceleration_step ticks (the database's frame interval: interpolated
//     playback is smooth between stored frames and kinks at them, so a
//     spacing of one tick at 60 Hz would double every kink). Samples taken
//     within jump_window_s of a jump (the transition's blend, where
//     inertialization moves the pose fastest) or whose three poses include
//     a jump's first pose are kept apart from the rest: p99 at jumps
//     against p99 elsewhere is how visible the jumps are.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "measure/histogram.hpp"
#include "mmvk/database/animation_data.hpp"

namespace mmvk::crowd {

// The joints the figures read, per side (left, right); -1 when the skeleton
// has no such joint.
struct LegJoints {
  std::array<int, 2> upper{-1, -1};    // hip joint (@left_upper_leg)
  std::array<int, 2> lower{-1, -1};    // knee (@left_lower_leg)
  std::array<int, 2> ankle{-1, -1};    // @left_foot
  std::array<int, 2> contact{-1, -1};  // AnimationData::contact_joints (the toe, else the ankle)

  bool has_feet() const { return contact[0] >= 0 && contact[1] >= 0; }
  bool has_knees() const;
};
LegJoints find_leg_joints(const AnimationData& animation);

struct MotionMeterParams {
  LegJoints legs;
  std::array<float, 2> planted_height{0.0f, 0.0f};  // metres, per foot
  double dt = 1.0 / 30.0;                            // seconds per tick
  std::uint32_t acceleration_step = 1;               // k, in ticks (>= 1)
  double jump_window_s = 0.3;                        // seconds after a jump that count as at the jump
};

// NaN: not measured (no samples, or the input was not given).
struct MotionFigures {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double foot_sliding_cm_s = kNone;
  double foot_sliding_before_ik_cm_s = kNone;
  double foot_lock_fraction = kNone;
  double ik_reach_clamped_fraction = kNone;
  double knee_speed_p99_deg_s = kNone;
  double foot_height_in_contact_cm_mean = kNone;
  double foot_height_in_contact_cm_p95 = kNone;
  double pose_acceleration_p99_m_s2 = kNone;           // away from jumps
  double pose_acceleration_p99_at_jumps_m_s2 = kNone;  // within a jump's samples
};

class MotionMeter {
 public:
  // `streams` characters or clips of `joints` joints.
  MotionMeter(std::size_t streams, std::size_t joints, const MotionMeterParams& params);

  // One tick of every stream. Sizes: shown and animated [streams x joints]
  // world metres (animated: before foot IK, or empty); contacts [streams]
  // FootContact bits; locked and clamped [streams x 2] (left, right) or
  // empty; jumped [streams] (1: a jump's first pose) or empty.
  struct Tick {
    std::span<const glm::vec3> shown;
    std::span<const glm::vec3> animated;
    std::span<const std::uint8_t> contacts;
    std::span<const std::uint8_t> locked;
    std::span<const std::uint8_t> clamped;
    std::span<const std::uint8_t> jumped;
  };
  void record(const Tick& tick);
  // The next tick of `stream` does not continue its last one (a new clip).
  void restart(std::size_t stream) { seen_[stream] = 0; }

  MotionFigures figures() const;

 private:
  void record_feet(std::size_t s, const Tick& tick);
  void record_knees(std::size_t s, std::span<const glm::vec3> pose);
  void record_acceleration(std::size_t s, std::span<const glm::vec3> pose, bool near_jump);

  std::size_t streams_, joints_;
  MotionMeterParams params_;
  std::size_t ring_;                       // 2k + 1 poses kept per stream
  std::uint64_t jump_ticks_;               // samples this many ticks after a jump are at it
  std::uint64_t ticks_ = 0;
  std::vector<std::uint64_t> seen_;        // [streams] ticks since the stream (re)started
  std::vector<std::uint64_t> since_jump_;  // [streams] ticks since its last jump's first pose
  std::vector<glm::vec3> last_points_, last_points_animated_;  // [streams x 2 feet x (toe, ankle)]
  std::vector<std::uint8_t> last_contacts_;                // [streams]
  std::vector<float> last_knee_;                           // [streams x 2] radians, NaN: none
  std::vector<glm::vec3> poses_;                           // [ring x streams x joints]
  double sliding_sum_ = 0.0, sliding_animated_sum_ = 0.0;  // m/s
  std::uint64_t sliding_samples_ = 0;
  bool have_animated_ = false, have_locks_ = false, have_clamps_ = false;
  std::uint64_t contact_ticks_ = 0, locked_ticks_ = 0, foot_ticks_ = 0, clamped_ticks_ = 0;
  Histogram knee_speed_;       // deg/s
  Histogram height_;           // |height| cm
  double height_sum_cm_ = 0.0;
  Histogram acceleration_, acceleration_at_jumps_;  // m/s^2
};

}  // namespace mmvk::crowd
