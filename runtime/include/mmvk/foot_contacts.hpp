// Foot contacts: which feet are planted on each frame of a clip. One
// detection serves the animation section (AnimationData::contacts, which the
// runtime's foot locking reads) and the foot_contact feature channel, so the
// two never disagree.
#pragma once

#include <cstdint>
#include <string>

namespace mmvk {

// Contact bits of AnimationData::contacts. kContactLeft / kContactRight say
// the foot is planted (what the foot_contact channel and foot locking read);
// the heel and toe bits say which of its points touch the ground, where the
// skeleton has both (the heel is the ankle joint, the toe the ball of the foot).
enum FootContact : std::uint8_t {
  kContactLeft = 1u << 0,
  kContactRight = 1u << 1,
  kContactLeftHeel = 1u << 2,
  kContactLeftToe = 1u << 3,
  kContactRightHeel = 1u << 4,
  kContactRightToe = 1u << 5,
};

// How foot contacts are detected at build time. A foot is in contact on a
// frame when its contact bone is both low and slow:
//   height < floor + max_height, where height is the bone's model-space y
//     (metres) and floor is the floor_percentile of that bone's height over
//     the clip (or 0 with height_above_clip_floor = false): skeletons put the
//     toe joint at different heights above the ground (Bandai 0.042 m, CMU
//     0.073 m when planted), and recordings put the ground at different y;
//   and speed (length of the central-difference velocity, m/s) < max_speed.
// docs/animation.md gives the measurements behind the defaults.
struct FootContactParams {
  // Bone references (see find_bone); when the toe role does not resolve
  // (DAZ skeletons have no toe) the ankle ("@left_foot"/"@right_foot") is
  // used, with max_height + ankle_height_extra when heights are absolute.
  std::string left_bone = "@left_toe";
  std::string right_bone = "@right_toe";
  float max_height = 0.02f;          // metres above the floor
  float max_speed = 0.6f;            // m/s
  float ankle_height_extra = 0.06f;  // metres, absolute heights only
  bool height_above_clip_floor = true;
  float floor_percentile = 0.05f;    // in [0, 1]
};

}  // namespace mmvk
