#include "backends/driver_cache.hpp"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "mmvk/common/input_text.hpp"

namespace mmvk::crowd {

namespace {

std::string shown(const std::filesystem::path& path) { return printable_text(path.string(), 4096); }

// The folder itself when it exists, else the nearest one above it: what
// Mesa would create the cache in.
std::filesystem::path existing_folder(std::filesystem::path folder) {
  std::error_code ec;
  while (!folder.empty() && !std::filesystem::exists(folder, ec) && folder != folder.parent_path()) {
    folder = folder.parent_path();
  }
  return folder;
}

// A probe file created exclusively and removed: access(W_OK) says yes to
// root on a read-only mount's folder, and only a write says whether one
// works.
std::string probe_write(const std::filesystem::path& folder) {
  std::string name = (folder / ".mmvk-cache-probe-XXXXXX").string();
  std::vector<char> buffer(name.begin(), name.end());
  buffer.push_back('\0');
  const int fd = ::mkstemp(buffer.data());
  if (fd < 0) return std::strerror(errno);
  const bool wrote = ::write(fd, "x", 1) == 1;
  const int saved = errno;
  ::close(fd);
  ::unlink(buffer.data());
  return wrote ? std::string() : std::strerror(saved);
}

}  // namespace

std::filesystem::path driver_shader_cache_folder() {
  if (const char* dir = std::getenv("MESA_SHADER_CACHE_DIR"); dir != nullptr && *dir != '\0') return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && std::filesystem::path(xdg).is_absolute()) {
    return std::filesystem::path(xdg) / "mesa_shader_cache";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home != '\0') {
    return std::filesystem::path(home) / ".cache" / "mesa_shader_cache";
  }
  return {};
}

std::string driver_cache_problem(const std::filesystem::path& folder, std::uint64_t min_free_bytes) {
  const std::filesystem::path existing = existing_folder(folder);
  std::error_code ec;
  if (existing.empty() || !std::filesystem::is_directory(existing, ec)) {
    return shown(existing.empty() ? folder : existing) + " is not a folder";
  }
  if (const std::string failed = probe_write(existing); !failed.empty()) {
    return shown(existing) + " cannot be written (" + failed + ")";
  }
  struct statvfs stats {};
  if (::statvfs(existing.c_str(), &stats) != 0) return shown(existing) + ": " + std::strerror(errno);
  const std::uint64_t free_bytes = std::uint64_t(stats.f_bavail) * std::uint64_t(stats.f_frsize);
  if (free_bytes < min_free_bytes) {
    return shown(existing) + " has " + std::to_string(free_bytes >> 20) + " MiB free (under " +
           std::to_string(min_free_bytes >> 20) + " MiB)";
  }
  return {};
}

std::string guard_driver_shader_cache() {
  if (std::getenv("MESA_SHADER_CACHE_DISABLE") != nullptr) return {};  // the user's choice stands
  const std::filesystem::path folder = driver_shader_cache_folder();
  if (folder.empty()) return {};  // Mesa finds no folder either and runs without a disk cache
  const std::string problem = driver_cache_problem(folder);
  if (problem.empty()) return {};
  ::setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
  return "the Vulkan driver's shader cache folder " + problem +
         ", so the driver runs with its disk cache off (MESA_SHADER_CACHE_DISABLE=true)";
}

}  // namespace mmvk::crowd
