// The motion figures of the database's own clips, measured exactly as the
// crowd's (motion_meter.hpp): each clip played frame by frame at the
// database's fps, its stored poses placed at its stored roots. They are the
// floor the crowd is compared with: contacts are detected with thresholds,
// so a flagged foot may still move a little in the clips too. Figures that
// only the crowd has (before IK, locks, clamps, jumps) stay NaN.
#pragma once

#include <array>

#include "mmvk/database/database.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "measure/motion_meter.hpp"

namespace mmvk::crowd {

struct ClipQuality {
  MotionFigures figures;
  // Per foot (left, right): the median height of the contact joint over the
  // frames where the foot is flagged in contact, metres above the clips'
  // ground (the joint sits above the sole); the floor the crowd's
  // foot_height_in_contact is measured from. 0 without contacts.
  std::array<float, 2> planted_height{0.0f, 0.0f};
};

// Figures all NaN when the database has no animation.
ClipQuality measure_clip_quality(const Database& database, ThreadPool& pool);

}  // namespace mmvk::crowd
