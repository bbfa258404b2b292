// VulkanBruteForce: the brute-force kernels on VulkanSearch's slots.
#include "mmvk/vulkan/vulkan_brute_force.hpp"

#include <utility>

#include "brute_force_kernel.hpp"
#include "vulkan_search_impl.hpp"

namespace mmvk::vulkan {

namespace {

using detail::BruteForceKernel;
using detail::PageCommands;

class BruteForceRun final : public detail::SearchKernel {
 public:
  explicit BruteForceRun(BruteForceKernel kernel) : kernel_(std::move(kernel)) {}
  std::uint64_t scratch_pairs_per_query(std::uint32_t k) const override { return kernel_.scratch_pairs_per_query(k); }
  Status record(const Context& context, const PageCommands& page) const override {
    return kernel_.record(context, page.commands, page.layout, page.count, page.k, page.chunk, page.tile);
  }
  // Every query evaluates every scanned row.
  std::uint64_t rows_evaluated(std::uint32_t, std::uint32_t count) const override {
    return std::uint64_t{count} * kernel_.shape().scan_rows;
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> warm_up_variants() const override {
    return kernel_.variant_keys();
  }
  std::vector<std::string_view> kernel_names() const override { return kernel_.kernel_names(); }
  std::uint64_t device_bytes() const override { return 0; }  // pipelines only

 private:
  BruteForceKernel kernel_;
};

}  // namespace

VulkanBruteForce::VulkanBruteForce(std::unique_ptr<Impl> impl) : VulkanSearch(std::move(impl)) {}

Result<std::unique_ptr<VulkanBruteForce>> VulkanBruteForce::create(Context& context, const Database& database,
                                                                   const VulkanSearchOptions& options) {
  MMVK_ASSIGN_OR_RETURN(std::unique_ptr<Impl> impl, Impl::begin(context, database, options, true));
  MMVK_ASSIGN_OR_RETURN(BruteForceKernel kernel,
                        BruteForceKernel::create(context, impl->pipeline_layout.get(), impl->shape, options.max_batch,
                                                 options.max_k, options.max_tile));
  impl->kernel = std::make_unique<BruteForceRun>(std::move(kernel));
  MMVK_TRY(impl->create_slots(impl->kernel->scratch_pairs_per_query(options.max_k)));
  MMVK_TRY(impl->finish());
  return std::unique_ptr<VulkanBruteForce>(new VulkanBruteForce(std::move(impl)));
}

}  // namespace mmvk::vulkan
