// An opt-in helper for applications that keep the Context's pipeline cache
// on disk between runs (the mmvk CLI and the crowd host do, through
// LazyContext (lazy_context.hpp), under
// $XDG_CACHE_HOME/mmvk or ~/.cache/mmvk): one file per device in a
// directory the application names. mmvk itself never calls these; the
// library reads no environment variables and chooses no directory.
//
//   auto context = mmvk::vulkan::Context::create().value();
//   std::string note = mmvk::vulkan::load_pipeline_cache_file(*context, dir);   // "" or why it was not used
//   ... create searches, warm_up(), search ...
//   mmvk::Status saved = mmvk::vulkan::save_pipeline_cache_file(*context, dir);
//
// The file frames the driver's blob with a magic, a version, the blob's
// size and a checksum, so a truncated or damaged file is detected before
// the driver sees it; the blob's own header then ties it to the device and
// driver build (a stale file is ignored and overwritten by the next save).
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"

namespace mmvk::vulkan {

// `directory` / "vulkan-<vendorID>-<deviceID>.pipeline-cache" (hex ids) for
// the Context's device.
std::filesystem::path pipeline_cache_file(const Context& context, const std::filesystem::path& directory);

// Encodes / decodes the file's bytes (decode errors name what is wrong).
std::string encode_pipeline_cache_file(std::span<const std::byte> blob);
Result<std::vector<std::byte>> decode_pipeline_cache_file(std::string_view bytes);

// Merges the device's file in `directory` into the Context's cache.
// Returns "" when it was used or does not exist yet, otherwise a note for
// the user saying why it was ignored (not a regular file, over 256 MiB,
// unreadable, damaged, another driver build); never fails, the cache stays
// usable either way.
std::string load_pipeline_cache_file(Context& context, const std::filesystem::path& directory);

// Writes the Context's current cache to its file in `directory` (created
// with its parents if missing), atomically: a crash mid-write leaves the
// previous file, and whatever stood at the file's name (a symlink, a device
// node) is replaced, never written through. Errors name the path.
Status save_pipeline_cache_file(const Context& context, const std::filesystem::path& directory);

}  // namespace mmvk::vulkan
