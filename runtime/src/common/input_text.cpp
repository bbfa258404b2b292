#include "mmvk/common/input_text.hpp"

#include <algorithm>
#include <cstdio>

namespace mmvk {

std::string printable_text(std::string_view text, std::size_t max_bytes) {
  const std::size_t shown = std::min(text.size(), max_bytes);
  std::string out;
  out.reserve(shown + 3);
  for (std::size_t i = 0; i < shown; ++i) {
    const auto byte = static_cast<unsigned char>(text[i]);
    if (byte >= 0x20 && byte < 0x7F) {
      out += static_cast<char>(byte);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\x%02x", byte);
      out += escaped;
    }
  }
  if (shown < text.size()) out += "...";
  return out;
}

std::string quoted_text(std::string_view text, std::size_t max_bytes) {
  // Appended rather than "\"" + ...: GCC 12 warns (-Wrestrict) on that form.
  std::string out(1, '"');
  out += printable_text(text, max_bytes);
  out += '"';
  return out;
}

}  // namespace mmvk
