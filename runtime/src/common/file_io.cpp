#include "mmvk/common/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstring>

namespace mmvk {

namespace {

namespace fs = std::filesystem;

std::string describe_errno(const fs::path& path, const char* what, int error = errno) {
  return path.string() + ": " + what + ": " + std::strerror(error);
}

const char* file_kind(mode_t mode) {
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

Error too_large(const fs::path& path, std::uint64_t bytes, bool at_least, std::uint64_t limit) {
  const std::string name = limit == kMaxFileBytes ? " (kMaxFileBytes) for one mmvk input file" : " bytes for this input";
  return make_error(path.string() + ": " + (at_least ? "more than " : "") + std::to_string(bytes) +
                    " bytes, over the limit of " + std::to_string(limit) + name);
}

// Closes the descriptor on every path out of read_file.
struct Descriptor {
  int fd = -1;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

Result<std::string> read_file(const fs::path& path, const ReadOptions& options) {
  // Checked before the file is opened: opening a device can have effects
  // of its own (a tape rewinds, a watchdog arms), and a FIFO opened for
  // reading blocks until someone writes.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return make_error(path.string() + ": no such file");
    return make_error(describe_errno(path, "cannot open for reading"));
  }
  if (S_ISDIR(st.st_mode)) return make_error(path.string() + ": is a directory, expected a file");
  if (!S_ISREG(st.st_mode) && !options.allow_stream) {
    return make_error(path.string() + ": is " + file_kind(st.st_mode) + ", not a regular file (read from files only)");
  }
  if (S_ISREG(st.st_mode) && std::uint64_t(st.st_size) > options.max_bytes) {
    return too_large(path, std::uint64_t(st.st_size), false, options.max_bytes);
  }
  // O_NONBLOCK: a FIFO replaced in between cannot block the open either.
  Descriptor file{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)};
  if (file.fd < 0) return make_error(describe_errno(path, "cannot open for reading"));
  struct stat opened {};
  if (::fstat(file.fd, &opened) != 0) return make_error(describe_errno(path, "cannot read"));
  if (S_ISDIR(opened.st_mode) || (!S_ISREG(opened.st_mode) && !options.allow_stream)) {
    return make_error(path.string() + ": changed while it was opened; not read");
  }
  // Reads block from here on: a stream's writer is waited for (a FIFO that
  // no one had open at the open() reads as empty instead).
  if (!S_ISREG(opened.st_mode)) ::fcntl(file.fd, F_SETFL, ::fcntl(file.fd, F_GETFL) & ~O_NONBLOCK);
  std::string contents;
  if (S_ISREG(opened.st_mode)) contents.reserve(static_cast<std::size_t>(std::min<std::uint64_t>(
                                   std::uint64_t(opened.st_size), options.max_bytes)));
  std::array<char, 1 << 16> chunk;
  for (;;) {
    const ssize_t got = ::read(file.fd, chunk.data(), chunk.size());
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) return make_error(describe_errno(path, "read error"));
    if (got == 0) break;
    if (contents.size() + std::size_t(got) > options.max_bytes) {
      return too_large(path, contents.size() + std::size_t(got), true, options.max_bytes);
    }
    contents.append(chunk.data(), std::size_t(got));
  }
  return contents;
}

void append_f32_le(std::string& bytes, std::span<const float> values) {
  const std::size_t start = bytes.size();
  bytes.resize(start + values.size() * 4);
  char* out = bytes.data() + start;
  if (values.empty()) return;  // memcpy with a null pointer is undefined, even for 0 bytes
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(out, values.data(), values.size_bytes());
  } else {
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::uint32_t bits = std::bit_cast<std::uint32_t>(values[i]);
      for (int b = 0; b < 4; ++b) out[4 * i + b] = static_cast<char>((bits >> (8 * b)) & 0xFF);
    }
  }
}

void decode_f32_le(std::string_view bytes, std::span<float> values) {
  if (values.empty()) return;  // memcpy with a null pointer is undefined, even for 0 bytes
  const char* in = bytes.data();
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(values.data(), in, values.size_bytes());
  } else {
    for (std::size_t i = 0; i < values.size(); ++i) {
      std::uint32_t bits = 0;
      for (int b = 0; b < 4; ++b) bits |= std::uint32_t{static_cast<std::uint8_t>(in[4 * i + b])} << (8 * b);
      values[i] = std::bit_cast<float>(bits);
    }
  }
}

Result<std::vector<float>> read_f32_rows(const std::filesystem::path& path, std::uint32_t cols,
                                         std::optional<std::uint64_t> expected_rows, const ReadOptions& options) {
  if (cols == 0) return make_error(path.string() + ": a float32 row file needs at least one value per row");
  MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(path, options));
  const std::size_t row_bytes = std::size_t{cols} * 4;
  if (expected_rows && bytes.size() != *expected_rows * row_bytes) {
    return make_error(path.string() + ": " + std::to_string(bytes.size()) + " bytes, expected " +
                      std::to_string(*expected_rows) + " rows x " + std::to_string(cols) +
                      " values x 4 bytes = " + std::to_string(*expected_rows * row_bytes) +
                      " (raw little-endian float32)");
  }
  if (!expected_rows && (bytes.empty() || bytes.size() % row_bytes != 0)) {
    return make_error(path.string() + ": " + std::to_string(bytes.size()) + " bytes is not a whole number of rows of " +
                      std::to_string(cols) + " float32 values (" + std::to_string(row_bytes) + " bytes each)");
  }
  std::vector<float> values(bytes.size() / 4);
  decode_f32_le(bytes, values);
  return values;
}

Status write_f32_rows(const std::filesystem::path& path, std::span<const float> values) {
  std::string bytes;
  append_f32_le(bytes, values);
  return write_file_atomically(path, bytes);
}

}  // namespace mmvk
