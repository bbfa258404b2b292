// The foot contacts in `mmvk inspect` (text and JSON): per foot, how often
// it is flagged planted, and its toe and heel in contact, and how fast the
// flagged point still moves horizontally (the floor under the crowd's foot
// sliding before any foot locking).
#pragma once

#include <nlohmann/json.hpp>

#include "mmvk/database/database.hpp"

namespace mmvk::cli {

// Lines under print_animation's; nothing without an animation section.
void print_contacts(const Database& database);
// {"toe_joints", "heel_joints", "legacy", "params", "feet": {"left": {"planted",
// "toe", "heel"}, "right": ...}}, each with "joint", "frames", "fraction",
// "mean_speed_cm_s" and "fast_fraction"; null without an animation section.
// The planted foot's speed is its point on the ground's: the heel while only
// the heel bit is set, else "joint" (the toe), as the crowd measures sliding.
nlohmann::json contacts_json(const Database& database);

}  // namespace mmvk::cli
