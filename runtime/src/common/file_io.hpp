// Whole-file reads and atomic writes (temp file in the same directory, fsync,
// rename): a failed write never destroys what the user had.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "mmvk/status.hpp"

namespace mmvk::detail {

Result<std::string> read_file(const std::filesystem::path& path);
Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace mmvk::detail
