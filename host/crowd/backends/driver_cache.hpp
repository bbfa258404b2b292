// Mesa's Vulkan drivers (lavapipe, RADV, ANV) keep a shader cache on disk
// and write it through memory-mapped files from a thread of their own: on a
// full disk that thread dies with SIGBUS and takes the process with it
// (mmvk's own cache files fail cleanly there). A host calls
// guard_driver_shader_cache() before it creates its first Vulkan context:
// where the driver's cache folder cannot be written or has little room, the
// driver's disk cache is turned off for this process. Host code: the
// library reads and sets no environment variable.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace mmvk::crowd {

// Free bytes the driver's cache folder must have (Mesa's cache grows to
// about 1 GiB, its index file is mapped whole when it starts).
inline constexpr std::uint64_t kMinDriverCacheFreeBytes = std::uint64_t{64} << 20;

// Mesa's cache folder as Mesa finds it: $MESA_SHADER_CACHE_DIR, else
// $XDG_CACHE_HOME/mesa_shader_cache, else $HOME/.cache/mesa_shader_cache;
// empty when none is set.
std::filesystem::path driver_shader_cache_folder();

// Why `folder` cannot hold the driver's cache: not a folder, not writable
// (a probe file is created and removed in it, or in the nearest folder
// above it that exists, where Mesa would create it) or under
// `min_free_bytes` free; "" when it can.
std::string driver_cache_problem(const std::filesystem::path& folder,
                                 std::uint64_t min_free_bytes = kMinDriverCacheFreeBytes);

// Sets MESA_SHADER_CACHE_DISABLE=true when the driver's cache folder has a
// problem and the user has not chosen (MESA_SHADER_CACHE_DISABLE already
// set). Returns a note saying why it did, or "". Call it before the first
// Vulkan instance: Mesa reads the variable when a device is created.
std::string guard_driver_shader_cache();

}  // namespace mmvk::crowd
