// The checks every mmvk JSON input gets (manifests, schemas, pose targets,
// and hosts' own files such as the crowd's scenario): valid JSON, nothing
// after the value but whitespace, no NUL byte anywhere (the JSON parser
// mmvk uses stops at one, so "{}\0anything" would pass), no key twice in
// one object (the parser would keep the last one silently), and at most
// kMaxJsonDepth nested arrays and objects (the writers and readers of
// nlohmann::json recurse, so a deeper document would overflow the stack).
// The check takes time linear in the text's size.
#pragma once

#include <cstddef>
#include <string_view>

#include "mmvk/common/status.hpp"

namespace mmvk {

// Nested arrays and objects allowed in a JSON input; mmvk's own files nest
// at most 5 levels.
inline constexpr std::size_t kMaxJsonDepth = 256;

// Errors name `source` and the byte offset and reason of a syntax error
// ("not valid JSON at byte 12: syntax error while parsing object key -
// unexpected '}'"), the duplicate key, the NUL byte's offset or the depth.
Status check_json_text(std::string_view text, std::string_view source);

}  // namespace mmvk
