// The foot sliding of the database itself, measured exactly as the crowd's
// (mean horizontal speed of a foot between two consecutive frames of a clip
// where it is flagged in contact at both), from the stored poses placed at
// the stored roots. It is the floor the crowd cannot go below without foot
// IK: contacts are detected with a speed threshold, so a flagged foot may
// still move a little.
#pragma once

#include "mmvk/database.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::crowd {

// cm/s; NaN when the database has no animation, no contact joints or no
// contact pairs.
double database_foot_sliding_cm_s(const Database& database, ThreadPool& pool);

}  // namespace mmvk::crowd
