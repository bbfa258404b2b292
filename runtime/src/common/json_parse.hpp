// JSON parsing for manifests and schemas: nlohmann::json keeps the last of
// two equal keys in an object without a word, so a manifest with "fps" twice
// would silently use one of them. parse_json_object_text rejects that, naming
// the key.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "mmvk/status.hpp"

namespace mmvk::detail {

// Parses `text`; errors name `source`: "not valid JSON", or a duplicate key.
Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& source);

}  // namespace mmvk::detail
