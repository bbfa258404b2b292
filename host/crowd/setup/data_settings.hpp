// The crowd settings a data set was tuned with: the "crowd" block of its
// manifest, which the build keeps in the database
// (Database::crowd_settings), so `mmvk crowd`, the stepped crowd and
// mmvk.Crowd all run a shipped set (host/crowd/data/*/manifest.json) with its
// tuning, and a user's own data can carry its own. A setting given by the
// caller (crowd_settings.hpp) overrides the data's.
//
//   "crowd": {
//     "correction_half_life": 0.07,   // seconds, > 0
//     "continuing_bias": -2.5,        // finite
//     "continuing_multiplier": 1.0,   // finite, >= 0
//     "exclusion_window": 0           // frames, an integer >= 0
//   }
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

struct DataSettings {
  std::optional<float> correction_half_life;
  std::optional<float> continuing_bias;
  std::optional<float> continuing_multiplier;
  std::optional<std::uint32_t> exclusion_window;
};

// The block's keys, in the order above, for messages and help.
std::string data_setting_keys();

// Parses `json` (an object's text, or empty: no settings). Errors name
// `source`, "crowd." and the key: an unknown key, a value out of range.
Result<DataSettings> parse_data_settings(std::string_view json, const std::string& source);
// The database's block (Database::crowd_settings).
Result<DataSettings> data_settings(const Database& database, const std::string& source);
// "--correction-half-life 0.07" for each setting the block holds, or "" (help texts).
std::string describe_data_settings(const DataSettings& settings);

}  // namespace mmvk::crowd
