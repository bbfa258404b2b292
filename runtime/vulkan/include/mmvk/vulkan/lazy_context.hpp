// A Vulkan context made on first use, for hosts that offer the Vulkan
// backends beside the CPU ones: listing the registry's names (--help) or
// running a CPU backend never touches the driver, and the first Vulkan
// backend made creates the context, merging in the pipeline cache file kept
// in `cache_directory` (pipeline_cache_file.hpp). The host names that
// directory (the mmvk CLI and crowd use $XDG_CACHE_HOME/mmvk): the library
// reads no environment variable.
//
//   mmvk::vulkan::LazyContext vulkan({.context = {}, .cache_directory = dir});  // declared before the backends
//   mmvk::BackendRegistry registry = mmvk::cpu_backends();
//   MMVK_TRY(vulkan.add_backends(registry));
//   ... registry.make(spec, database), search ...
//   mmvk::Status saved = vulkan.save_pipeline_cache();  // nothing when no context was made
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "mmvk/search/backends.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/vulkan/context.hpp"
#include "mmvk/vulkan/vulkan_search.hpp"

namespace mmvk::vulkan {

struct LazyContextOptions {
  ContextOptions context;                  // the device, application name, validation, ...
  std::filesystem::path cache_directory;   // the pipeline cache file's folder; empty: no file
};

class LazyContext {
 public:
  explicit LazyContext(LazyContextOptions options = {});
  LazyContext(const LazyContext&) = delete;
  LazyContext& operator=(const LazyContext&) = delete;

  // The context, created on the first call; a failure (no Vulkan driver or
  // device, the requested index out of range) is kept and returned again,
  // so one missing device is reported once, the same way, by every backend.
  Result<Context*> get();
  // The context when get() has made one, else null (never creates it).
  Context* created() const { return context_.get(); }

  // Why the pipeline cache file was not used ("" when it was, when it did
  // not exist yet, or without a cache directory); set by get().
  const std::string& pipeline_cache_note() const { return pipeline_cache_note_; }
  // Writes the context's pipeline cache to its file in the cache directory;
  // nothing when no context was made or without a cache directory.
  Status save_pipeline_cache() const;

  // Adds vulkan-brute, vulkan-clusters and vulkan-nprobe (backends.hpp),
  // made on get() with `options`. This object must outlive the registry and
  // every backend made from it. Error when one of the names is already
  // registered.
  Status add_backends(BackendRegistry& registry, const VulkanSearchOptions& options = {});

 private:
  LazyContextOptions options_;
  std::unique_ptr<Context> context_;
  std::optional<Error> failure_;
  std::string pipeline_cache_note_;
};

}  // namespace mmvk::vulkan
