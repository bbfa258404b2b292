#include "import/scene_import_child.hpp"

#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <string>
#include <thread>

#include "common/byte_codec.hpp"

namespace mmvk::detail {

namespace {

void write_motion(Writer& out, const Motion& motion) {
  const std::size_t joints = motion.joint_count();
  out.f32(motion.fps);
  out.u32(motion.frame_count);
  out.u32(static_cast<std::uint32_t>(joints));
  for (std::size_t j = 0; j < joints; ++j) {
    out.str(motion.skeleton.names[j]);
    out.u32(static_cast<std::uint32_t>(motion.skeleton.parents[j]));
    for (int a = 0; a < 3; ++a) out.f32(motion.skeleton.rest_offsets[j][a]);
  }
  // glm's vec3 and quat are tightly packed floats (x, y, z[, w]).
  out.f32_array({&motion.local_positions.data()->x, motion.local_positions.size() * 3});
  out.f32_array({&motion.local_rotations.data()->x, motion.local_rotations.size() * 4});
}

// The child's result as bytes: 1 and the import, or 0 and the error.
std::string encode(const Result<SceneImport>& imported) {
  Writer out;
  out.u8(imported.ok() ? 1 : 0);
  if (!imported.ok()) {
    out.str(imported.message());
    return std::move(out.bytes());
  }
  out.f32(imported->metres_per_unit);
  out.str(imported->units_from);
  out.str(imported->axes_from);
  out.u32(static_cast<std::uint32_t>(imported->animations.size()));
  for (const SceneAnimation& animation : imported->animations) {
    out.str(animation.name);
    write_motion(out, animation.motion);
  }
  return std::move(out.bytes());
}

bool read_motion(Reader& in, Motion& motion) {
  std::uint32_t joints = 0;
  if (!in.f32(motion.fps) || !in.u32(motion.frame_count) || !in.u32(joints)) return false;
  motion.skeleton.names.resize(joints);
  motion.skeleton.parents.resize(joints);
  motion.skeleton.rest_offsets.resize(joints);
  for (std::uint32_t j = 0; j < joints; ++j) {
    std::uint32_t parent = 0;
    glm::vec3& offset = motion.skeleton.rest_offsets[j];
    if (!in.str(motion.skeleton.names[j]) || !in.u32(parent) || !in.f32(offset.x) || !in.f32(offset.y) ||
        !in.f32(offset.z)) {
      return false;
    }
    motion.skeleton.parents[j] = static_cast<int>(parent);
  }
  const std::uint64_t samples = std::uint64_t{motion.frame_count} * joints;
  if (samples > in.left() / 28) return false;  // 3 + 4 floats per sample
  motion.local_positions.resize(samples);
  motion.local_rotations.resize(samples);
  in.f32_array({&motion.local_positions.data()->x, samples * 3});
  in.f32_array({&motion.local_rotations.data()->x, samples * 4});
  return true;
}

Result<SceneImport> decode(std::string_view bytes, const std::string& source) {
  Reader in(bytes, 0, bytes.size());
  const Error corrupt = make_error(source + ": the import's child process returned a damaged result");
  std::uint8_t ok = 0;
  if (!in.u8(ok)) return corrupt;
  if (!ok) {
    std::string message;
    return in.str(message) ? make_error(message) : corrupt;
  }
  SceneImport out;
  std::uint32_t count = 0;
  if (!in.f32(out.metres_per_unit) || !in.str(out.units_from) || !in.str(out.axes_from) || !in.u32(count) ||
      count > in.left()) {
    return corrupt;
  }
  out.animations.resize(count);
  for (SceneAnimation& animation : out.animations) {
    if (!in.str(animation.name) || !read_motion(in, animation.motion)) return corrupt;
  }
  return in.left() == 0 ? Result<SceneImport>(std::move(out)) : Result<SceneImport>(corrupt);
}

bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return true;
}

bool read_all(int fd, std::string& out) {
  if (::lseek(fd, 0, SEEK_SET) != 0) return false;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof(buffer));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return false;
    if (n == 0) return true;
    out.append(buffer, static_cast<std::size_t>(n));
  }
}

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// In the child: its address space capped at what it maps now plus the budget.
void limit_memory(std::uint64_t budget) {
  if (kAddressSanitizer) return;
  long pages = 0;
  if (FILE* statm = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
    std::fclose(statm);
  }
  const std::uint64_t mapped = std::uint64_t(pages > 0 ? pages : 0) * std::uint64_t(::sysconf(_SC_PAGESIZE));
  const rlimit limit{mapped + budget, mapped + budget};
  (void)::setrlimit(RLIMIT_AS, &limit);
}

[[noreturn]] void run_child(int fd, const std::filesystem::path& path, const SceneImportOptions& options,
                            const SceneReader& read) {
  limit_memory(options.memory_budget_bytes);
  SceneImportOptions here = options;
  here.isolate = false;
  const bool written = write_all(fd, encode(read(path, here)));
  ::_exit(written ? 0 : 3);
}

// Waits for the child until the deadline; kills it past it. False: killed.
bool wait_for(pid_t child, double timeout_seconds, int& status) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  auto pause = std::chrono::microseconds(100);
  for (;;) {
    const pid_t done = ::waitpid(child, &status, WNOHANG);
    if (done == child || (done < 0 && errno != EINTR)) return true;
    if (std::chrono::steady_clock::now() >= deadline) {
      ::kill(child, SIGKILL);
      while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return false;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
}

std::string megabytes(std::uint64_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

}  // namespace

Result<SceneImport> read_scene_in_child(const std::filesystem::path& path, const SceneImportOptions& options,
                                        const SceneReader& read) {
  const std::string source = path.string();
  if (!(options.timeout_seconds > 0.0) || options.memory_budget_bytes == 0) {
    return make_error(source + ": the scene import's timeout_seconds and memory_budget_bytes must be positive");
  }
  // The result goes through an anonymous file, read once the child is gone.
  const int fd = ::memfd_create("mmvk-scene-import", MFD_CLOEXEC);
  if (fd < 0) return make_error(source + ": could not create the import's result file: " + std::strerror(errno));
  const pid_t child = ::fork();
  if (child < 0) {
    const int code = errno;
    ::close(fd);
    return make_error(source + ": could not start the import's child process: " + std::strerror(code));
  }
  if (child == 0) run_child(fd, path, options, read);
  int status = 0;
  const bool finished = wait_for(child, options.timeout_seconds, status);
  std::string bytes;
  const bool read_back = finished && WIFEXITED(status) && WEXITSTATUS(status) == 0 && read_all(fd, bytes);
  ::close(fd);
  if (!finished) {
    return make_error(source + ": assimp did not finish reading it within " +
                      std::to_string(static_cast<long long>(options.timeout_seconds)) +
                      " s; the file is damaged or far larger than it looks");
  }
  if (WIFSIGNALED(status)) {
    return make_error(source + ": assimp crashed reading it (signal " + std::to_string(WTERMSIG(status)) + ", " +
                      ::strsignal(WTERMSIG(status)) + ") or ran past the " + megabytes(options.memory_budget_bytes) +
                      " it may allocate; the file is damaged or uses what assimp cannot read");
  }
  if (!read_back) return make_error(source + ": the import's child process failed (exit status " +
                                    std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
  Result<SceneImport> imported = decode(bytes, source);
  if (!imported.ok() && imported.message().ends_with("std::bad_alloc")) {
    return make_error(imported.message() + " (past the " + megabytes(options.memory_budget_bytes) +
                      " the import may allocate)");
  }
  return imported;
}

}  // namespace mmvk::detail
