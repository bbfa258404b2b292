// The units section of `mmvk inspect` (text and JSON): whether units and data
// are plausible at a glance, the metres per file unit each clip was imported
// with, the skeleton's standing height, and the walk and run speeds the
// crowd measures (host/crowd/steering/gait_speeds.hpp).
#pragma once

#include <nlohmann/json.hpp>

#include "mmvk/database/database.hpp"

namespace mmvk::cli {

// A few lines: "units: ...", "standing height: ...", "speeds: ...".
void print_units(const Database& database);
// {"metres_per_unit": [{"value", "clips", "name"}], "standing_height_m",
//  "walk_mps", "run_mps", "run_note"}; unknown figures are null.
nlohmann::json units_json(const Database& database);

}  // namespace mmvk::cli
