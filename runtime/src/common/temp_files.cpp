#include "common/temp_files.hpp"

#include <signal.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <system_error>

namespace mmvk::detail {

namespace {

namespace fs = std::filesystem;

constexpr std::string_view kTempMarker = ".tmp-";
constexpr std::size_t kRandomDigits = 12;

bool is_hex(std::string_view text) {
  for (const char c : text) {
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  }
  return !text.empty();
}

// kill(pid, 0) fails with ESRCH only when no process has that PID (EPERM:
// one runs, as another user).
bool process_running(long pid) { return ::kill(pid_t(pid), 0) == 0 || errno != ESRCH; }

}  // namespace

fs::path folder_of(const fs::path& target) { return target.has_parent_path() ? target.parent_path() : fs::path("."); }

fs::path temp_name(const fs::path& target, unsigned attempt) {
  std::uint64_t random = 0;
  if (::getrandom(&random, sizeof(random), GRND_NONBLOCK) != static_cast<ssize_t>(sizeof(random))) {
    random = (std::uint64_t(::getpid()) << 32) ^ (std::uint64_t(attempt) * 0x9E3779B97F4A7C15ull);
  }
  char suffix[48];
  std::snprintf(suffix, sizeof(suffix), ".tmp-%ld-%012llx", long(::getpid()),
                static_cast<unsigned long long>(random & 0xFFFFFFFFFFFFull));
  std::string name = target.filename().string();
  if (name.size() > 200) name = "mmvk";  // stay under NAME_MAX with the suffix
  return folder_of(target) / (name + suffix);
}

long temp_writer_pid(const std::string& name) {
  const std::size_t marker = name.rfind(kTempMarker);
  if (marker == std::string::npos || marker == 0) return 0;
  const std::string_view rest = std::string_view(name).substr(marker + kTempMarker.size());
  const std::size_t dash = rest.find('-');
  if (dash == std::string_view::npos || rest.size() - dash - 1 != kRandomDigits || !is_hex(rest.substr(dash + 1))) {
    return 0;
  }
  long pid = 0;
  const auto [end, error] = std::from_chars(rest.data(), rest.data() + dash, pid);
  if (error != std::errc{} || end != rest.data() + dash || pid <= 0) return 0;
  return pid;
}

std::size_t reap_stale_temps(const fs::path& folder) {
  std::error_code ec;
  fs::directory_iterator it(folder, ec);
  if (ec) return 0;
  std::size_t removed = 0;
  const long self = long(::getpid());
  for (const fs::directory_entry& entry : it) {
    const std::string name = entry.path().filename().string();
    const long pid = temp_writer_pid(name);
    if (pid == 0 || pid == self || process_running(pid)) continue;
    // Only this user's own regular files: never a link, never another's.
    struct stat st {};
    if (::lstat(entry.path().c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid()) continue;
    if (::unlink(entry.path().c_str()) == 0) ++removed;
  }
  return removed;
}

}  // namespace mmvk::detail
