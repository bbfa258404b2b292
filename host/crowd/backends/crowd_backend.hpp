// The search a crowd run uses: a backend made by name, behind the
// controller's deferred interface (AsyncSearch). Every backend goes through
// the same deferred path (results applied one tick after the search), so
// that the chosen frames are equal across backends for the same seed; on
// Vulkan the search really runs asynchronously and overlaps the host's next
// step, on the CPU backends it runs at submit.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "backends/host_backends.hpp"
#include "mmvk/search/async_search.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::crowd {

struct CrowdSearch {
  HostBackends backends;                     // declared first: outlives the backend
  std::unique_ptr<SearchBackend> backend;
  std::unique_ptr<AsyncSearch> deferred;     // on `backend`
  std::string device;                        // backend->device(): "llvmpipe (...) (Vulkan device 0, ...)", "cpu, 2 threads"
  std::string pipeline_cache_note;           // why a pipeline cache file was not used, or ""
  // What "auto" picked and why ("auto: no GPU, ..."); empty for a backend named.
  std::string choice;
  std::string driver_cache_note;             // why the driver's shader cache is off (driver_cache.hpp), or ""
};

// The CPU backends "auto" picks where there is no GPU, the fastest for a
// crowd on the CPU: fast-box on a database of up to kAutoClusterFrames
// frames, clusters above, where its pruning pays for itself
// (bench/RESULTS.md, "--backend auto", has the measurements).
inline constexpr const char* kAutoCpuBackend = "fast-box";
inline constexpr const char* kAutoLargeCpuBackend = "clusters";
inline constexpr std::uint32_t kAutoClusterFrames = 50'000;
// The Vulkan backend "auto" picks on a GPU.
inline constexpr const char* kAutoGpuBackend = "vulkan-brute";

// The backends `mmvk crowd --backend` accepts ("auto", then HostBackends'),
// one line each with its description, for --help.
std::string crowd_backend_help();

// "auto", or `name` as given: a Vulkan backend (kAutoGpuBackend) where a
// Vulkan device is a GPU (discrete, integrated or virtual) or `device`
// names one; else, where the only Vulkan devices run on the CPU (llvmpipe)
// or there is none, kAutoCpuBackend, or kAutoLargeCpuBackend for a database
// of more than kAutoClusterFrames `frames`. `reason` gets why.
std::string resolve_backend(const std::string& name, std::optional<std::uint32_t> device, std::uint32_t frames,
                            std::string& reason);

// Makes `name` ("auto": resolve_backend) from HostBackends on `database` for up to
// `agents` queries per tick. `device` picks the Vulkan device (none: the
// best one). A Vulkan context starts from the pipeline cache file in
// `cache_dir` (none when empty); save_crowd_pipeline_cache keeps it.
// Errors: an unknown name (listing the known ones), no Vulkan device, a
// database too large, --device with a CPU backend.
Result<CrowdSearch> make_crowd_search(const std::string& name, std::optional<std::uint32_t> device,
                                      const Database& database, std::uint32_t agents, ThreadPool& pool,
                                      const std::filesystem::path& cache_dir);

// Writes the Vulkan context's pipeline cache to its file in the `cache_dir`
// given to make_crowd_search, so that the next run's kernels compile without
// a stall; nothing for a CPU backend or an empty `cache_dir`.
Status save_crowd_pipeline_cache(const CrowdSearch& search);

}  // namespace mmvk::crowd
