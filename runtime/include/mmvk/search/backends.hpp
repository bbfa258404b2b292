// Making search backends by name: one table from a name (plus the options
// in a BackendSpec) to a SearchBackend, used by the CLI, the benchmarks, the
// tests and the hosts alike. A backend's name() is its key.
//
// The registry is a value, not global state: cpu_backends() returns the CPU
// entries, and mmvk::vulkan::add_backends(registry, context, options) adds
// the GPU ones, so mmvk::runtime has no Vulkan dependency. A made backend
// says where it runs itself (SearchBackend::device()).
//
//   mmvk::ThreadPool pool;
//   mmvk::BackendSpec spec{.name = "clusters", .pool = &pool};
//   MMVK_ASSIGN_OR_RETURN(auto backend, mmvk::cpu_backends().make(spec, database));
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/search/cluster_search.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/search/fast_search.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

class ThreadPool;

// What to make. Fields a backend does not use are ignored.
struct BackendSpec {
  std::string name = "fast-box";
  // The threads of the CPU backends other than the reference (fast-*,
  // clusters*): required for them, and it must outlive the backend. Also
  // spreads k-means training when a cluster table is trained.
  ThreadPool* pool = nullptr;
  // fast-brute, fast-box: prune is set from the name.
  FastSearchOptions fast = {};
  // The cluster backends (clusters*, vulkan-clusters, vulkan-nprobe) need a
  // ClusterTable: `clusters` when set (it must come from this database, else
  // the backend reports an error; it is copied or uploaded at creation, so
  // it need not outlive the backend), otherwise one trained with `kmeans`.
  const ClusterTable* clusters = nullptr;
  KMeansParams kmeans = {};
  // *-nprobe: clusters searched per query, >= 1.
  std::uint32_t nprobe = 4;
  // clusters, clusters-nprobe: the pruning bounds; nprobe is set from the
  // name and `nprobe` above.
  ClusterSearchOptions cluster = {};
  // A device backend's own options (the Vulkan ones' largest batch and k,
  // query tile, warm-up) are not here: they are given where its entries
  // are added (mmvk::vulkan::add_backends), so this library knows no device.
};

using BackendFactory =
    std::function<Result<std::unique_ptr<SearchBackend>>(const BackendSpec& spec, const Database& database)>;

struct BackendEntry {
  std::string name;         // equal to the made backend's name()
  std::string description;  // one line, for --help texts
  BackendFactory make;
  // Needs a ClusterTable (BackendSpec::clusters, or one trained from
  // BackendSpec::kmeans), so a caller knows whether to load one.
  bool uses_cluster_table = false;
  // Reads BackendSpec::nprobe, so a host can refuse an --nprobe that would
  // otherwise be ignored without a word.
  bool uses_nprobe = false;
};

class BackendRegistry {
 public:
  // Error when the name is empty or already taken, or make is empty.
  Status add(BackendEntry entry);

  // In the order they were added.
  const std::vector<BackendEntry>& entries() const { return entries_; }
  // nullptr when no backend has that name.
  const BackendEntry* find(std::string_view name) const;
  // "reference, fast-brute, ..." in order.
  std::string names() const;
  // One line per backend, "<indent><name>  <description>\n", names padded
  // to one column: the list a host's --help prints.
  std::string help(std::string_view indent = "  ") const;

  // Makes spec.name over `database`; an unknown name is an error that lists
  // the known ones.
  Result<std::unique_ptr<SearchBackend>> make(const BackendSpec& spec, const Database& database) const;

 private:
  std::vector<BackendEntry> entries_;
};

// reference, fast-brute, fast-box, clusters, clusters-nprobe.
BackendRegistry cpu_backends();

// cpu_backends().make(spec, database).
Result<std::unique_ptr<SearchBackend>> make_backend(const BackendSpec& spec, const Database& database);

// For the cluster backends' factories: spec.clusters when set, else a table
// trained with spec.kmeans into `trained` (on spec.pool when set). The
// pointer is valid while spec and `trained` are.
Result<const ClusterTable*> spec_cluster_table(const BackendSpec& spec, const Database& database,
                                               std::optional<ClusterTable>& trained);

}  // namespace mmvk
