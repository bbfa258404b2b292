// Where the mmvk commands (query, crowd) keep files between runs,
// such as the Vulkan pipeline cache (mmvk/vulkan/pipeline_cache_file.hpp).
// Host code: the library reads no environment variables.
#pragma once

#include <filesystem>
#include <optional>

namespace mmvk::cli {

// $XDG_CACHE_HOME/mmvk when XDG_CACHE_HOME is an absolute path (the XDG
// base directory spec ignores relative ones), else $HOME/.cache/mmvk;
// nullopt when neither is set, and the caller runs without a cache. The
// directory may not exist yet.
std::optional<std::filesystem::path> user_cache_directory();

}  // namespace mmvk::cli
