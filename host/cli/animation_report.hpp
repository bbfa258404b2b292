// The animation section in `mmvk inspect` (text and JSON) and its open
// layout for `mmvk export --animation`.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::cli {

// One text line (or two) describing the section, or saying it is absent.
void print_animation(const Database& database);
// {"present": false} or the skeleton, sizes and contact statistics.
nlohmann::json animation_json(const Database& database);

// `mmvk export --animation out.f32`: the section in an open layout for other
// tools: little-endian float32, row-major [frames x columns], one row per
// database frame, and a JSON sidecar naming the columns, the skeleton, the
// clips and the conventions. Error when the database has no animation.
Status export_animation(const Database& database, const std::string& source, const std::filesystem::path& values,
                        const std::filesystem::path& sidecar);

}  // namespace mmvk::cli
