// The animation section in `mmvk inspect` (text and JSON) and its open
// layout for `mmvk export --animation`.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "mmvk/database.hpp"
#include "mmvk/status.hpp"

namespace mmvk::cli {

// One text line (or two) describing the section, or saying it is absent.
void print_animation(const Database& database);
// {"present": false} or the skeleton, sizes and contact statistics.
nlohmann::json animation_json(const Database& database);

}  // namespace mmvk::cli
