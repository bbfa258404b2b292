#include "user_cache_dir.hpp"

#include <cstdlib>

namespace mmvk::cli {

std::optional<std::filesystem::path> user_cache_directory() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && std::filesystem::path(xdg).is_absolute()) {
    return std::filesystem::path(xdg) / "mmvk";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".cache" / "mmvk";
  }
  return std::nullopt;
}

}  // namespace mmvk::cli
