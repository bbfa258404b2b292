// Private device nodes for tests of how mmvk treats non-regular files: a
// null, zero or full device made with mknod inside a test's own temporary
// folder (never the machine's /dev), and FIFOs. mknod needs root (or
// CAP_MKNOD) and a file system that allows device nodes: tests skip when it
// is refused.
#pragma once

#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <filesystem>
#include <string>

namespace mmvk::test {

// The Linux memory devices' numbers (major 1): what the node does when used.
enum class MemoryDevice : unsigned { Null = 3, Zero = 5, Full = 7, Urandom = 9 };

// Makes `path` a character device node behaving like /dev/null, /dev/zero,
// ... Returns false when mknod is not permitted here.
inline bool make_device_node(const std::filesystem::path& path, MemoryDevice device) {
  return ::mknod(path.c_str(), S_IFCHR | 0666, makedev(1, static_cast<unsigned>(device))) == 0;
}

inline bool make_fifo(const std::filesystem::path& path) { return ::mkfifo(path.c_str(), 0600) == 0; }

// The kind of file at `path` without following a symlink: "regular",
// "character device", "fifo", "symlink", "directory", "missing" or "other".
inline std::string file_type(const std::filesystem::path& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) return "missing";
  if (S_ISREG(st.st_mode)) return "regular";
  if (S_ISCHR(st.st_mode)) return "character device";
  if (S_ISFIFO(st.st_mode)) return "fifo";
  if (S_ISLNK(st.st_mode)) return "symlink";
  if (S_ISDIR(st.st_mode)) return "directory";
  return "other";
}

}  // namespace mmvk::test
