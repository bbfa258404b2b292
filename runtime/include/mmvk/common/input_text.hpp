// Text from input files (keys, names, tokens) as messages show it: anyone
// can write those files, so an escape sequence in a manifest key must not
// retitle or clear the terminal that prints the error, and a megabyte key
// must not make a megabyte error line. The BVH parser's rule, used by every
// message that echoes input text.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace mmvk {

// At most this many bytes of an input's text are shown, then "...".
inline constexpr std::size_t kMaxShownInputBytes = 64;

// `text` with every byte outside printable ASCII (0x20-0x7E: control
// characters, DEL and the bytes of non-ASCII characters) written as \xHH,
// cut to its first `max_bytes` bytes plus "..." when longer.
std::string printable_text(std::string_view text, std::size_t max_bytes = kMaxShownInputBytes);

// printable_text in double quotes: "key".
std::string quoted_text(std::string_view text, std::size_t max_bytes = kMaxShownInputBytes);

}  // namespace mmvk
