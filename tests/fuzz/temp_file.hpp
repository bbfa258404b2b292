// For loaders that take a path: one scratch file per fuzzing process,
// rewritten for every input (under /dev/shm when it exists, so no disk I/O).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace mmvk::fuzz {

inline std::filesystem::path write_scratch(std::string_view bytes, const char* extension) {
  const std::filesystem::path dir = std::filesystem::exists("/dev/shm") ? "/dev/shm" : "/tmp";
  const std::filesystem::path path = dir / ("mmvk-fuzz-" + std::to_string(::getpid()) + extension);
  if (std::FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fwrite(bytes.data(), 1, bytes.size(), file);
    std::fclose(file);
  }
  return path;
}

}  // namespace mmvk::fuzz
