// Foot contacts: which feet are planted on each frame of a clip, and on which
// of their points. One detection serves the animation section
// (AnimationData::contacts, which the runtime's foot locking reads) and the
// foot_contact feature channel, so the two never disagree.
#pragma once

#include <cstdint>
#include <string>

#include "mmvk/common/status.hpp"

namespace mmvk {

// Contact bits of AnimationData::contacts. The heel and toe bits say which
// points of the foot are planted (the heel is the ankle joint, the toe the
// ball of the foot; a skeleton without a toe joint, such as DAZ's, has heel
// bits only). kContactLeft / kContactRight say the foot is planted (what the
// foot_contact channel and foot locking read; the locker anchors the toe when
// the toe bit is set, else the heel). The detection sets the planted bit
// exactly when the heel or toe bit is; AnimationData::validate() requires a
// heel or toe bit to come with the planted bit, and allows a planted bit
// alone (contacts made in code), which the foot locker reads as the toe.
enum FootContact : std::uint8_t {
  kContactLeft = 1u << 0,
  kContactRight = 1u << 1,
  kContactLeftHeel = 1u << 2,
  kContactLeftToe = 1u << 3,
  kContactRightHeel = 1u << 4,
  kContactRightToe = 1u << 5,
};
inline constexpr std::uint8_t kContactAllBits = 0x3F;

// The bits of one side (0 left, 1 right).
constexpr std::uint8_t contact_planted_bit(int side) { return side == 0 ? kContactLeft : kContactRight; }
constexpr std::uint8_t contact_heel_bit(int side) { return side == 0 ? kContactLeftHeel : kContactRightHeel; }
constexpr std::uint8_t contact_toe_bit(int side) { return side == 0 ? kContactLeftToe : kContactRightToe; }
// Both feet planted (a double support, or standing).
constexpr bool both_feet_planted(std::uint8_t bits) {
  return (bits & (kContactLeft | kContactRight)) == (kContactLeft | kContactRight);
}
// The bits with left and right exchanged (a mirrored motion's contacts):
// the planted bits sit side by side, the heel and toe pairs two apart.
constexpr std::uint8_t mirror_contact_bits(std::uint8_t bits) {
  return static_cast<std::uint8_t>(((bits & kContactLeft) << 1) | ((bits & kContactRight) >> 1) |
                                   ((bits & (kContactLeftHeel | kContactLeftToe)) << 2) |
                                   ((bits & (kContactRightHeel | kContactRightToe)) >> 2));
}

// How foot contacts are detected at build time, for the toe and the heel of
// each foot separately, on the joint's model-space trajectory, in steps of
// speed_step_seconds (rounded to whole frames, at least one):
//   height = y - floor (metres), floor = the floor_percentile of that joint's
//     height over the clip (or 0 for the toe and heel_height_extra for the
//     heel with height_above_clip_floor = false): skeletons put their joints
//     at different heights above the ground (a planted Bandai toe at
//     0.042 m, CMU's at 0.073 m) and recordings put the ground at different y;
//   speed = the horizontal (x, z) distance the joint moves over the step,
//     per second. Vertical motion (a heel rolling down onto the ground) is
//     left to the height.
// Hysteresis: a step enters contact when its speed < enter_speed and the
// height at both its ends < enter_height, and stays in contact while they
// are < exit_speed and < exit_height; a frame is in contact when a step in
// contact covers it. Then gaps shorter than min_gap_seconds are closed and
// contacts shorter than min_contact_seconds removed (runs that touch the
// clip's first or last frame are kept as they are: their length is unknown).
// The foot is planted where its toe or heel is; a gap of the planted foot
// shorter than min_gap_seconds (the heel lifting a frame before the toe
// lands) is closed by holding the point that was planted before it.
// docs/animation.md gives the measurements behind the defaults (Bandai
// locomotion: 38% of frames planted per foot, the flagged toe moving
// 1.8 cm/s on average).
struct FootContactParams {
  // Bone references (see find_bone). A side whose toe does not resolve
  // (DAZ skeletons have no toe) is detected on the heel alone.
  std::string left_toe = "@left_toe";
  std::string right_toe = "@right_toe";
  std::string left_heel = "@left_foot";
  std::string right_heel = "@right_foot";
  float enter_height = 0.02f;               // metres above the floor
  float exit_height = 0.03f;                // metres above the floor, >= enter_height
  float enter_speed = 0.05f;                // m/s, horizontal
  float exit_speed = 0.075f;                // m/s, horizontal, >= enter_speed
  float min_contact_seconds = 0.1f;         // shorter contacts are removed
  float min_gap_seconds = 0.1f;             // shorter gaps are closed
  float speed_step_seconds = 1.0f / 30.0f;  // the step speeds are measured over
  bool height_above_clip_floor = true;
  float floor_percentile = 0.05f;           // in [0, 1]
  float heel_height_extra = 0.06f;          // metres, the heel's floor when heights are absolute
};

// The fields of FootContactParams by their manifest names, for code that
// treats them alike (the manifest reader, validation, the .mmdb, `mmvk
// inspect`): the bones, then the numbers (every field but
// height_above_clip_floor). The .mmdb stores them in this order.
template <class Params, class Fn>
void for_each_contact_bone(Params& params, Fn fn) {
  fn("left_toe", params.left_toe);
  fn("right_toe", params.right_toe);
  fn("left_heel", params.left_heel);
  fn("right_heel", params.right_heel);
}
template <class Params, class Fn>
void for_each_contact_number(Params& params, Fn fn) {
  fn("enter_height", params.enter_height);
  fn("exit_height", params.exit_height);
  fn("enter_speed", params.enter_speed);
  fn("exit_speed", params.exit_speed);
  fn("min_contact_seconds", params.min_contact_seconds);
  fn("min_gap_seconds", params.min_gap_seconds);
  fn("speed_step_seconds", params.speed_step_seconds);
  fn("floor_percentile", params.floor_percentile);
  fn("heel_height_extra", params.heel_height_extra);
}

// Bones non-empty; every threshold and duration finite and >= 0; exit
// thresholds >= enter thresholds; floor_percentile in [0, 1]. Errors name
// `where` and the field ("db.json: contacts.exit_speed: ...").
Status validate_foot_contact_params(const FootContactParams& params, const std::string& where);

}  // namespace mmvk
