#include "mmvk/vulkan/lazy_context.hpp"

#include <utility>

#include "mmvk/vulkan/backends.hpp"
#include "mmvk/vulkan/pipeline_cache_file.hpp"

namespace mmvk::vulkan {

LazyContext::LazyContext(LazyContextOptions options) : options_(std::move(options)) {}

Result<Context*> LazyContext::get() {
  if (context_) return context_.get();
  // Creating a Vulkan instance is slow (lavapipe: tens of ms) and a missing
  // driver does not come back within a run: fail once, the same way.
  if (failure_) return *failure_;
  Result<std::unique_ptr<Context>> created = Context::create(options_.context);
  if (!created) {
    failure_ = created.error();
    return *failure_;
  }
  context_ = std::move(created).value();
  if (!options_.cache_directory.empty()) {
    pipeline_cache_note_ = load_pipeline_cache_file(*context_, options_.cache_directory);
  }
  return context_.get();
}

Status LazyContext::save_pipeline_cache() const {
  if (!context_ || options_.cache_directory.empty()) return {};
  return save_pipeline_cache_file(*context_, options_.cache_directory);
}

Status LazyContext::add_backends(BackendRegistry& registry, const VulkanSearchOptions& options) {
  return vulkan::add_backends(registry, [this]() { return get(); }, options);
}

}  // namespace mmvk::vulkan
