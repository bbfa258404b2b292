// The checks every mmvk JSON input gets (manifests, schemas, pose targets,
// and hosts' own files such as the crowd's scenario): valid JSON, nothing
// after the value but whitespace, no NUL byte anywhere (the JSON parser
// mmvk uses stops at one, so "{}\0anything" would pass), and no key twice
// in one object (the parser would keep the last one silently).
#pragma once

#include <string_view>

#include "mmvk/status.hpp"

namespace mmvk {

// Errors name `source` and the duplicate key or the NUL byte's offset.
Status check_json_text(std::string_view text, std::string_view source);

}  // namespace mmvk
