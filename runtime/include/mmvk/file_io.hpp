// File I/O shared by the library and its tools: whole-file reads, atomic
// writes (temp file in the same directory, fsync, rename: a failed write
// never destroys what the user had), and headerless little-endian float32
// row files ([rows x cols], row-major), the format of query files, custom
// channel sidecars and `mmvk export`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/status.hpp"

namespace mmvk {

// The largest file read_file() reads: 4 GiB, several times the largest
// database mmvk builds from real motion capture (the CMU volume set with
// animation is about 200 MB). A larger file (or an endless device such as
// /dev/zero) is an error naming the limit, not an allocation failure.
inline constexpr std::uint64_t kMaxFileBytes = std::uint64_t{4} << 30;

// The whole file. Errors: a directory, unreadable, over kMaxFileBytes.
Result<std::string> read_file(const std::filesystem::path& path);
Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes);
// Checks up front that write_file_atomically(path, ...) can succeed as far as
// the path goes: path is not a directory, its folder exists and is
// writable. Hosts call it before long work (a database build) whose result
// would otherwise be lost at the end. Errors name the path or folder.
Status check_writable(const std::filesystem::path& path);

// The float32 codec every mmvk file uses, independent of the host's byte
// order. decode: precondition bytes.size() >= 4 * values.size().
void append_f32_le(std::string& bytes, std::span<const float> values);
void decode_f32_le(std::string_view bytes, std::span<float> values);

// Reads a float32 row file of `cols` values per row (cols >= 1). Errors name
// the path: unreadable, a size that is not a whole number of rows, no rows,
// or (when expected_rows is given) another row count. Values are returned
// as stored; callers that need finite values check them.
Result<std::vector<float>> read_f32_rows(const std::filesystem::path& path, std::uint32_t cols,
                                         std::optional<std::uint64_t> expected_rows = std::nullopt);
// Writes `values` (any whole number of rows) atomically.
Status write_f32_rows(const std::filesystem::path& path, std::span<const float> values);

}  // namespace mmvk
