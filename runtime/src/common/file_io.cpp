#include "mmvk/file_io.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <fstream>

namespace mmvk {

namespace {
std::string describe_errno(const std::filesystem::path& path, const char* what) {
  return path.string() + ": " + what + ": " + std::strerror(errno);
}
}  // namespace

Result<std::string> read_file(const std::filesystem::path& path) {
  // An ifstream opens a directory and reads it as empty, which every loader
  // would then report as an empty or truncated file.
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return make_error(path.string() + ": is a directory, expected a file");
  // A regular file's size is known up front; anything else (a pipe, a
  // device such as /dev/zero) is bounded while it is read.
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  const auto too_large = [&](std::uintmax_t bytes, const char* qualifier) {
    return make_error(path.string() + ": " + qualifier + std::to_string(bytes) + " bytes, over the limit of " +
                      std::to_string(kMaxFileBytes) + " (kMaxFileBytes) for one mmvk input file");
  };
  if (!error && size > kMaxFileBytes) return too_large(size, "");
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path.string() + ": cannot open for reading");
  std::string contents;
  if (!error) contents.reserve(static_cast<std::size_t>(size));
  std::array<char, 1 << 16> chunk;
  while (in) {
    in.read(chunk.data(), chunk.size());
    const std::size_t got = static_cast<std::size_t>(in.gcount());
    if (contents.size() + got > kMaxFileBytes) return too_large(contents.size() + got, "more than ");
    contents.append(chunk.data(), got);
  }
  if (in.bad()) return make_error(path.string() + ": read error");
  return contents;
}

Status check_writable(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return make_error(path.string() + ": is a directory, expected a file");
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  if (!std::filesystem::is_directory(folder, error)) {
    return make_error(path.string() + ": cannot write there: folder " + folder.string() + " does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) return make_error(describe_errno(folder, "cannot write in this folder"));
  return {};
}

Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  // The temp file lives beside the target so rename() stays on one file system.
  std::filesystem::path temp = path;
  temp += ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return make_error(describe_errno(temp, "cannot create"));
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      Error error = make_error(describe_errno(temp, "write failed"));
      ::close(fd);
      ::unlink(temp.c_str());
      return error;
    }
    written += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    Error error = make_error(describe_errno(temp, "fsync failed"));
    ::close(fd);
    ::unlink(temp.c_str());
    return error;
  }
  if (::close(fd) != 0) {
    Error error = make_error(describe_errno(temp, "close failed"));
    ::unlink(temp.c_str());
    return error;
  }
  if (::rename(temp.c_str(), path.c_str()) != 0) {
    Error error = make_error(describe_errno(path, "cannot replace"));
    ::unlink(temp.c_str());
    return error;
  }
  // Make the rename itself durable.
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
  return {};
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
                                         std::optional<std::uint64_t> expected_rows) {
  if (cols == 0) return make_error(path.string() + ": a float32 row file needs at least one value per row");
  MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(path));
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
