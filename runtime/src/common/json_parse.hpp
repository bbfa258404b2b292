// JSON parsing for manifests and schemas: nlohmann::json keeps the last of
// two equal keys in an object without a word, so a manifest with "fps" twice
// would silently use one of them. parse_json_text rejects that, naming
// the key. Also the reading of a JSON number into a float that both share.
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "mmvk/common/status.hpp"

namespace mmvk::detail {

// Parses `text` with the checks of mmvk/common/json_check.hpp, in time linear in
// its size; errors name `source`: "not valid JSON at byte N: <reason>"
// (bytes after the value included), a NUL byte, a duplicate key or nesting
// deeper than kMaxJsonDepth. What it returns may be walked and dumped
// recursively.
Result<nlohmann::json> parse_json_text(std::string_view text, const std::string& source);

// A JSON number as a finite float; errors name `where` ("expected a number",
// or "not a finite number" beyond float's range).
Result<float> json_float(const nlohmann::json& value, const std::string& where);

}  // namespace mmvk::detail
