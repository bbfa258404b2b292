// The one writer for every mmvk output (mmvk/common/file_io.hpp: OutputFile).
//
// The old writer opened "<out>.tmp-<pid>" with O_CREAT | O_TRUNC, so a
// symlink planted at that predictable name redirected the write anywhere, and
// it renamed its temp file over whatever the target was: as root,
// `--out /dev/null` replaced the machine's /dev/null with a regular file.
// Here the kind of target decides first (replace a regular file, write a
// device or FIFO in place, write an open descriptor through itself), and the
// temp file is created exclusively under a random name.
#include "mmvk/common/file_io.hpp"

#include "common/temp_files.hpp"
#include "mmvk/common/number_text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <utility>

namespace mmvk {

namespace {

namespace fs = std::filesystem;

std::string describe_errno(const fs::path& path, const char* what, int error = errno) {
  return path.string() + ": " + what + ": " + std::strerror(error);
}

// /dev/stdout, /dev/stderr, /dev/fd/N, /proc/self/fd/N and /proc/<our pid>/fd/N
// name descriptors this process already has open (the shell's redirections):
// writing through the descriptor keeps what the shell asked for (`>>`
// appends), where reopening the name would start at offset 0 or, for a
// regular file behind it, replace the file.
std::optional<int> descriptor_name(const fs::path& path) {
  const std::string text = path.lexically_normal().string();
  if (text == "/dev/stdout") return 1;
  if (text == "/dev/stderr") return 2;
  if (text == "/dev/stdin") return 0;
  for (const std::string& prefix : {std::string("/dev/fd/"), std::string("/proc/self/fd/"),
                                   "/proc/" + std::to_string(::getpid()) + "/fd/"}) {
    if (!text.starts_with(prefix)) continue;
    int fd = -1;
    const char* first = text.data() + prefix.size();
    const char* last = text.data() + text.size();
    const auto [end, error] = std::from_chars(first, last, fd);
    if (first != last && error == std::errc{} && end == last && fd >= 0) return fd;
  }
  return std::nullopt;
}

enum class Way { Replace, InPlace, Descriptor };

struct Resolved {
  Way way = Way::Replace;
  fs::path target;             // Replace: the file renamed over; InPlace: the path opened
  int descriptor = -1;         // Descriptor
  std::optional<mode_t> mode;  // Replace: the permission bits of the file replaced
};

Result<Resolved> resolve_output(const fs::path& path, OutputPolicy policy) {
  if (path.empty()) return make_error("an output path is empty");
  struct stat link {};
  const bool linked = ::lstat(path.c_str(), &link) == 0;
  if (policy == OutputPolicy::CacheEntry) {
    // Whatever stands there is replaced as a directory entry; only a real
    // directory (rename cannot replace one by a file) is an error.
    if (linked && S_ISDIR(link.st_mode)) return make_error(path.string() + ": is a directory, expected a file");
    return Resolved{Way::Replace, path, -1, std::nullopt};
  }
  if (const std::optional<int> fd = descriptor_name(path)) {
    const int flags = ::fcntl(*fd, F_GETFL);
    if (flags < 0) return make_error(path.string() + ": descriptor " + std::to_string(*fd) + " is not open");
    if ((flags & O_ACCMODE) == O_RDONLY) {
      return make_error(path.string() + ": descriptor " + std::to_string(*fd) + " is open for reading only");
    }
    return Resolved{Way::Descriptor, path, *fd, std::nullopt};
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int error = errno;
    if (error != ENOENT) return make_error(describe_errno(path, "cannot write there", error));
    // Like cp, never create a file through a symlink to nothing: the link
    // could point anywhere.
    if (linked && S_ISLNK(link.st_mode)) {
      return make_error(path.string() + ": is a symlink to a missing file; not writing through it");
    }
    return Resolved{Way::Replace, path, -1, std::nullopt};
  }
  if (S_ISDIR(st.st_mode)) return make_error(path.string() + ": is a directory, expected a file");
  if (S_ISBLK(st.st_mode)) return make_error(path.string() + ": is a block device; mmvk writes no disk images");
  if (!S_ISREG(st.st_mode)) return Resolved{Way::InPlace, path, -1, std::nullopt};
  if (::access(path.c_str(), W_OK) != 0) return make_error(describe_errno(path, "cannot replace"));
  fs::path target = path;
  if (linked && S_ISLNK(link.st_mode)) {
    // Replace the file the link points to and keep the link.
    std::error_code ec;
    target = fs::canonical(path, ec);
    if (ec) return make_error(path.string() + ": cannot resolve the symlink: " + ec.message());
  }
  return Resolved{Way::Replace, target, -1, st.st_mode & 07777};
}

using detail::folder_of;

// A FIFO opened for writing: open() with O_NONBLOCK fails with ENXIO while
// no reader has it open, so the wait for one is a poll with a deadline
// instead of a blocking open that never returns. Once open, writes block
// as usual (the reader is there).
int open_fifo(const fs::path& path, std::chrono::milliseconds wait) {
  const auto deadline = std::chrono::steady_clock::now() + wait;
  for (;;) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd >= 0) {
      const int flags = ::fcntl(fd, F_GETFL);
      if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
        const int error = errno;
        ::close(fd);
        errno = error;
        return -1;
      }
      return fd;
    }
    if (errno != ENXIO || std::chrono::steady_clock::now() >= deadline) return -1;
    ::usleep(20000);
  }
}

}  // namespace

Result<OutputFile> OutputFile::open(const fs::path& path, OutputPolicy policy,
                                    std::chrono::milliseconds fifo_reader_wait) {
  MMVK_ASSIGN_OR_RETURN(const Resolved resolved, resolve_output(path, policy));
  OutputFile out;
  out.path_ = path;
  switch (resolved.way) {
    case Way::Descriptor: {
      // What stdio buffered for the same descriptor goes first.
      if (resolved.descriptor == 1) std::fflush(stdout);
      if (resolved.descriptor == 2) std::fflush(stderr);
      out.fd_ = ::fcntl(resolved.descriptor, F_DUPFD_CLOEXEC, 0);
      if (out.fd_ < 0) return make_error(describe_errno(path, "cannot use the descriptor"));
      return out;
    }
    case Way::InPlace: {
      // No O_CREAT and no O_TRUNC: the device or FIFO stays what it is.
      struct stat kind {};
      if (::stat(path.c_str(), &kind) == 0 && S_ISFIFO(kind.st_mode)) {
        out.fd_ = open_fifo(path, fifo_reader_wait);
        if (out.fd_ < 0 && errno == ENXIO) {
          return make_error(path.string() + ": is a FIFO that no reader opened within " +
                            number_text(double(fifo_reader_wait.count()) / 1000.0) + " s; not written");
        }
      } else {
        out.fd_ = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
      }
      if (out.fd_ < 0) return make_error(describe_errno(path, "cannot open for writing"));
      struct stat st {};
      if (::fstat(out.fd_, &st) != 0 || S_ISREG(st.st_mode) || S_ISDIR(st.st_mode)) {
        return make_error(path.string() + ": changed while it was opened; not written");
      }
      return out;
    }
    case Way::Replace:
      break;
  }
  out.target_ = resolved.target;
  detail::reap_stale_temps(folder_of(resolved.target));
  int error = 0;
  for (unsigned attempt = 0; attempt < 64; ++attempt) {
    fs::path temp = detail::temp_name(resolved.target, attempt);
    out.fd_ = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (out.fd_ >= 0) {
      out.temp_ = std::move(temp);
      break;
    }
    error = errno;
    if (error != EEXIST) break;
  }
  if (out.fd_ < 0) {
    return make_error(describe_errno(path, ("cannot create a temp file in " + folder_of(resolved.target).string()).c_str(),
                                     error));
  }
  // The replacement keeps the permissions of the file it replaces (a private
  // 0600 file stays private).
  if (resolved.mode && ::fchmod(out.fd_, *resolved.mode) != 0) {
    return make_error(describe_errno(out.temp_, "cannot set the permissions"));
  }
  return out;
}

OutputFile::OutputFile(OutputFile&& other) noexcept
    : path_(std::move(other.path_)),
      target_(std::move(other.target_)),
      temp_(std::exchange(other.temp_, fs::path())),
      fd_(std::exchange(other.fd_, -1)) {}

OutputFile& OutputFile::operator=(OutputFile&& other) noexcept {
  if (this != &other) {
    discard();
    path_ = std::move(other.path_);
    target_ = std::move(other.target_);
    temp_ = std::exchange(other.temp_, fs::path());
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

OutputFile::~OutputFile() { discard(); }

void OutputFile::discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!temp_.empty()) ::unlink(temp_.c_str());
  temp_.clear();
}

Status OutputFile::write(std::string_view bytes) {
  if (fd_ < 0) return make_error(path_.string() + ": written after it was closed");
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd_, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int error = n < 0 ? errno : EIO;
      discard();
      return make_error(describe_errno(path_, "write failed", error));
    }
    written += static_cast<std::size_t>(n);
  }
  return {};
}

Status OutputFile::commit() {
  if (fd_ < 0) return make_error(path_.string() + ": committed after it was closed");
  if (in_place()) {
    // fsync means nothing to a pipe or a device (EINVAL); a write error
    // there was already reported by write().
    const int fd = std::exchange(fd_, -1);
    if (::close(fd) != 0) return make_error(describe_errno(path_, "close failed"));
    return {};
  }
  if (::fsync(fd_) != 0) {
    Error error = make_error(describe_errno(path_, "fsync failed"));
    discard();
    return error;
  }
  const int fd = std::exchange(fd_, -1);
  if (::close(fd) != 0) {
    Error error = make_error(describe_errno(path_, "close failed"));
    discard();
    return error;
  }
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    Error error = make_error(describe_errno(path_, "cannot replace"));
    discard();
    return error;
  }
  temp_.clear();
  // Make the rename itself durable.
  const int dir_fd = ::open(folder_of(target_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return {};
}

Status write_file_atomically(const fs::path& path, std::string_view bytes, OutputPolicy policy) {
  MMVK_ASSIGN_OR_RETURN(OutputFile out, OutputFile::open(path, policy));
  MMVK_TRY(out.write(bytes));
  return out.commit();
}

Status check_writable(const fs::path& path, OutputPolicy policy) {
  MMVK_ASSIGN_OR_RETURN(const Resolved resolved, resolve_output(path, policy));
  if (resolved.way == Way::Descriptor) return {};
  if (resolved.way == Way::InPlace) {
    if (::access(path.c_str(), W_OK) != 0) return make_error(describe_errno(path, "cannot write"));
    return {};
  }
  const fs::path folder = folder_of(resolved.target);
  std::error_code error;
  if (!fs::is_directory(folder, error)) {
    return make_error(path.string() + ": cannot write there: folder " + folder.string() + " does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) return make_error(describe_errno(folder, "cannot write in this folder"));
  return {};
}

bool same_file(const fs::path& a, const fs::path& b) {
  struct stat sa {}, sb {};
  const bool a_exists = ::stat(a.c_str(), &sa) == 0;
  const bool b_exists = ::stat(b.c_str(), &sb) == 0;
  if (a_exists && b_exists) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (a_exists || b_exists) return false;
  // Two outputs not written yet: the same path once the folders' symlinks
  // and "." and ".." are resolved.
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ea), ea);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, eb), eb);
  return !ea && !eb && ca == cb;
}

bool is_stream_path(const fs::path& path) {
  if (descriptor_name(path)) return true;
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

}  // namespace mmvk
