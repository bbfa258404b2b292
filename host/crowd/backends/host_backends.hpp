// The search backends every mmvk entry point offers, assembled in this one
// place: the library's CPU backends (mmvk/search/backends.hpp) and, when mmvk is
// built with Vulkan, the Vulkan ones (mmvk/vulkan/backends.hpp) on a
// context created, on the chosen device, only when one of them is made
// (listing the names, or running a CPU backend, never touches the driver).
// `mmvk query`, `mmvk crowd`, mmvk.Search, mmvk.Crowd and the benchmarks
// all make their backends here, so they list the same names, and a backend
// shows the device text it reports itself (SearchBackend::device()) in each.
//
// The same in a build without Vulkan: the class hides the context, so
// no host writes a Vulkan #if of its own.
//
//   mmvk::crowd::HostBackends backends({.application_name = "my host"});
//   MMVK_ASSIGN_OR_RETURN(auto backend, backends.make({.name = "fast-box", .pool = &pool}, database));
//   std::puts(backend->device().c_str());
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/search/backends.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

struct HostBackendOptions {
  std::string application_name = "mmvk";  // the Vulkan instance's
  // The Vulkan device index (vkEnumeratePhysicalDevices); none: the best
  // device. Making a CPU backend with one set is an error naming
  // `device_option`, the host's word for it ("--device", "device").
  std::optional<std::uint32_t> device;
  std::string device_option = "--device";
  // The Vulkan pipeline cache file's folder (mmvk/vulkan/pipeline_cache_file.hpp);
  // empty: none, every run compiles from scratch.
  std::filesystem::path cache_directory;
};

// What a Vulkan backend takes beside its BackendSpec: the fields of
// vulkan::VulkanSearchOptions a host sets, here so that a host builds the
// same without Vulkan. The CPU backends ignore them.
struct DeviceSearchLimits {
  std::uint32_t max_batch = 1024;  // queries per device page, >= 1
  std::uint32_t max_k = kMaxK;     // the largest k a search may ask for
  std::uint32_t max_tile = 16;     // the largest query tile in registers (1, 4, 16 or 32)
  bool warm_up = true;             // compile every kernel variant at creation
};

// A Vulkan device as the loader reports it, for choosing a backend.
struct VulkanDeviceSummary {
  std::string name;
  bool gpu = false;  // a discrete, integrated or virtual GPU (not llvmpipe)
};

// The Vulkan context and its notes (host_backends.cpp defines it): opaque
// here, so that this class's layout is the same in every target that
// includes it, built with Vulkan or not.
struct HostDevice;

class HostBackends {
 public:
  explicit HostBackends(HostBackendOptions options = {});
  ~HostBackends();
  HostBackends(HostBackends&&) noexcept;
  HostBackends& operator=(HostBackends&&) noexcept;

  // Every backend, in order: the CPU ones, then the Vulkan ones when built
  // with Vulkan. For listing (names(), help(), find()); make() below makes.
  const BackendRegistry& registry() const { return listed_; }
  // True for a backend that runs on the CPU (one of cpu_backends()).
  static bool on_cpu(std::string_view name);
  // The Vulkan devices, in the order --device numbers them; empty without
  // a driver or device; nullopt in a build without Vulkan.
  static std::optional<std::vector<VulkanDeviceSummary>> vulkan_devices();

  // Makes spec.name over `database`; a Vulkan backend with `limits`. This
  // object must outlive what it makes. Before the first Vulkan context it
  // guards the driver's shader cache (driver_cache.hpp: driver_cache_note()
  // says what it did). Errors: an unknown name (listing the known ones),
  // a device with a CPU backend (naming the option), no Vulkan device, and
  // the backend's own.
  Result<std::unique_ptr<SearchBackend>> make(const BackendSpec& spec, const Database& database,
                                              const DeviceSearchLimits& limits = {});

  // Why the driver's shader cache was turned off, or "" (set by make()).
  const std::string& driver_cache_note() const { return driver_cache_note_; }
  // Why the pipeline cache file was not used, or "" (set by make()).
  std::string pipeline_cache_note() const;
  // Writes the Vulkan context's pipeline cache to its file in
  // cache_directory; nothing when no context was made or no directory set.
  Status save_pipeline_cache() const;

 private:
  HostBackendOptions options_;
  std::unique_ptr<HostDevice> device_;  // declared before the registries that make on it
  BackendRegistry listed_;
  std::string driver_cache_note_;
};

}  // namespace mmvk::crowd
