// File I/O shared by the library and its tools: the one reader and the one
// writer every mmvk input and output goes through, and headerless
// little-endian float32 row files ([rows x cols], row-major), the format of
// query files, custom channel sidecars and `mmvk export`.
//
// Reading: regular files only unless the caller accepts a stream, never more
// than a cap, and nothing that can block on a FIFO (docs/files-and-limits.md).
// Writing: a regular target is replaced atomically (an exclusive temp file in
// its folder, fsync, rename), so a failed write never destroys what the user
// had; a device, FIFO or socket is written in place, never renamed over.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/common/status.hpp"

namespace mmvk {

// The largest file read_file() reads by default: 4 GiB, several times the
// largest database mmvk builds from real motion capture (the CMU volume set
// with animation is about 200 MB). A larger file is an error naming the
// limit, not an allocation failure.
inline constexpr std::uint64_t kMaxFileBytes = std::uint64_t{4} << 30;
// The cap on a JSON input (manifest, schema, pose targets, crowd scenario):
// 64 MiB, thousands of times the largest real manifest.
inline constexpr std::uint64_t kMaxJsonBytes = std::uint64_t{64} << 20;

struct ReadOptions {
  // More bytes than this is an error naming the limit (checked against a
  // regular file's size before anything is read, and while a stream is read).
  std::uint64_t max_bytes = kMaxFileBytes;
  // false: only a regular file (or a symlink to one) is read; a FIFO, device
  // or socket is an error without a single read, so /dev/zero and a FIFO
  // nobody writes to fail at once. true: a pipe, FIFO, socket or character
  // device is read to its end or the cap (the caller documents the stream in
  // its --help); a FIFO without a writer reads as empty instead of blocking.
  bool allow_stream = false;
};

// The whole file. Errors name the path: missing, a directory, not a regular
// file (unless options.allow_stream), unreadable, over options.max_bytes.
Result<std::string> read_file(const std::filesystem::path& path, const ReadOptions& options = {});

// What a writer may do with whatever stands at its path.
enum class OutputPolicy : std::uint8_t {
  // A path the user named. A regular file, or a new one, is replaced
  // atomically; through a symlink, the file it points to is replaced (the
  // link stays); a symlink to nothing is an error. A character device, FIFO
  // or socket (/dev/null, a named pipe) is written in place, never renamed
  // over, and /dev/stdout, /dev/stderr, /dev/fd/N and /proc/self/fd/N are
  // written through that open descriptor (so `>>` appends). A FIFO waits
  // for a reader to open it, as a shell's `>` does, but at most
  // kFifoReaderWait: then it is an error, never a hang.
  UserPath,
  // A file mmvk names itself (a cache entry): whatever stands at the path,
  // a symlink or a device node included, is replaced by a regular file;
  // nothing is ever written through it.
  CacheEntry,
};

// How long opening a FIFO output waits for a reader.
inline constexpr std::chrono::milliseconds kFifoReaderWait{10000};

// One output being written: open() picks the way (see OutputPolicy) and, for
// a replaced file, creates the temp file exclusively (O_CREAT | O_EXCL |
// O_NOFOLLOW, a random name beside the target, so nothing planted there is
// followed: "<name>.tmp-<pid>-<random>"). A writer killed mid-write leaves
// its temp file behind, so open() first removes the temp files in the
// target's folder whose writer (the PID in their name) is no longer
// running, and which belong to this user. write() appends; commit() flushes (fsync) and renames the temp
// file over the target. Destroyed uncommitted, the temp file is removed and
// the target is left as it was. A replaced file keeps the mode of the file it
// replaces (new files: 0644 less the umask). Errors name the path and the step
// (a full disk, /dev/full, fails write() or commit()).
class OutputFile {
 public:
  // `fifo_reader_wait`: how long a FIFO waits for its reader.
  static Result<OutputFile> open(const std::filesystem::path& path, OutputPolicy policy = OutputPolicy::UserPath,
                                 std::chrono::milliseconds fifo_reader_wait = kFifoReaderWait);

  OutputFile(OutputFile&& other) noexcept;
  OutputFile& operator=(OutputFile&& other) noexcept;
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();

  Status write(std::string_view bytes);
  // After commit() (success or not) the OutputFile is closed.
  Status commit();

  // The path as given.
  const std::filesystem::path& path() const { return path_; }
  // True when written in place (a device, FIFO, socket or open descriptor).
  bool in_place() const { return temp_.empty(); }

 private:
  OutputFile() = default;
  void discard();

  std::filesystem::path path_;    // as given, for messages
  std::filesystem::path target_;  // the file renamed over (empty when in place)
  std::filesystem::path temp_;    // the temp file (empty when in place)
  int fd_ = -1;
};

// open + write + commit: the way every mmvk output is written.
Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                             OutputPolicy policy = OutputPolicy::UserPath);
// Checks up front, without writing or opening anything, that
// write_file_atomically(path, ...) can succeed as far as the path goes: not
// a directory, not a symlink to nothing, its folder exists and is writable
// (a file to replace), or the device, FIFO or descriptor is writable. Hosts
// call it before long work (a database build, a crowd run) whose result
// would otherwise be lost at the end. Errors name the path or folder.
Status check_writable(const std::filesystem::path& path, OutputPolicy policy = OutputPolicy::UserPath);

// True when the two paths name the same file: both exist and have the same
// device and inode (through symlinks, hard links or different spellings),
// or neither exists and they resolve to the same path. Hosts refuse an
// output that is the same file as an input or another output.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);
// True when `path` exists and is a character device, FIFO, socket or open
// descriptor name (written in place): two outputs may share such a path.
bool is_stream_path(const std::filesystem::path& path);

// A path a command reads or writes, named as the user gave it: `name` is the
// option ("--out") or the argument ("the database").
struct NamedPath {
  std::string name;
  std::filesystem::path path;
  bool output = false;
};
// What hosts call before any work (as cp and gcc -o do): every output passes
// check_writable, and no output is the same file (same_file) as an input or
// another output, unless it is a stream path (two outputs to one FIFO or
// device are written in turn, and a device is no input's storage). Errors
// name both options and paths.
Status check_command_paths(std::span<const NamedPath> paths);

// The float32 codec every mmvk file uses, independent of the host's byte
// order. decode: precondition bytes.size() >= 4 * values.size().
void append_f32_le(std::string& bytes, std::span<const float> values);
void decode_f32_le(std::string_view bytes, std::span<float> values);

// Reads a float32 row file of `cols` values per row (cols >= 1). Errors name
// the path: unreadable, a size that is not a whole number of rows, no rows,
// or (when expected_rows is given) another row count. Values are returned
// as stored; callers that need finite values check them. `options` as for
// read_file (a stream, a tighter cap).
Result<std::vector<float>> read_f32_rows(const std::filesystem::path& path, std::uint32_t cols,
                                         std::optional<std::uint64_t> expected_rows = std::nullopt,
                                         const ReadOptions& options = {});
// Writes `values` (any whole number of rows) atomically.
Status write_f32_rows(const std::filesystem::path& path, std::span<const float> values);

}  // namespace mmvk
