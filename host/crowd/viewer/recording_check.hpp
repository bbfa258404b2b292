// Checks that a Recording is consistent before the viewer encodes it, so a
// bug in the simulation shows as an error naming the field instead of a page
// that draws garbage.
#pragma once

#include "mmvk/common/status.hpp"
#include "output/recording.hpp"

namespace mmvk::crowd {

// Errors name the Recording field and the offending index: sizes that do not
// match agent_count x sample_count (x trajectory points, x joints x 3), a
// non-positive sample rate, agents without a sample, non-finite coordinates, trajectory times that
// are not ascending and positive, a joint parent that is not smaller than
// its child, pose_frames not ascending and unique, search events out of
// time order.
Status validate_recording(const Recording& recording);

}  // namespace mmvk::crowd
