// The methods of the suite's matrix, by the name its cells carry
// (suite/<dataset>/<schema>/<stream>/<method>/B:<batch>), and how each is
// made over a suite database:
//   reference, fast-brute, fast-box, clusters   mmvk's CPU backends (exact)
//   nprobe<N>                                   clusters-nprobe, N in {1, 4, 16, 64}
//   vulkan-brute, vulkan-clusters               mmvk's Vulkan backends (exact)
//   vulkan-nprobe<N>                            N in {1, 4, 16, 64}
//   faiss-flat, faiss-flat-1q, faiss-ivf<N>     FAISS peers, N in {1, 4, 16, 64}
//   pca-kdtree<C>                               PCA + KD-tree, C in {100, 300, 1000}
//   box-scan                                    the two-level box scan (exact)
// Peers that were not built (a package missing at configure time) are not
// listed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::vulkan {
class VulkanSearch;
}

namespace mmvk::bench {

// The cell names of every method built into this binary, in table order.
const std::vector<std::string>& suite_method_names();

// One made method and what the cells report about it beside the timing.
struct SuiteMethod {
  std::unique_ptr<SearchBackend> backend;
  // Returns the reference's frames (mmvk's exact backends and box-scan, by
  // their tests): recall is 1 without being measured.
  bool exact = false;
  double build_s = 0.0;       // index build (training, copies, upload), seconds
  double index_bytes = 0.0;   // host bytes beyond the database's feature matrix
  double device_bytes = 0.0;  // VulkanSearch::device_bytes(): database, tables, slots' scratch
  vulkan::VulkanSearch* vulkan = nullptr;  // for kernel timestamps
  // A peer's settings for this machine and the sweep that chose them
  // (PeerBackend::settings), the cell's label.
  std::string settings;
};

// What the methods of one database share, made on first use by the
// methods that need it.
class SuiteMethodFactory {
 public:
  // `cache_stem` names the cache files (cluster table, FAISS IVF index) in
  // the bench work folder. `database` and `pool` must outlive the factory.
  SuiteMethodFactory(const Database& database, ThreadPool& pool, std::string cache_stem);
  ~SuiteMethodFactory();

  Result<SuiteMethod> make(const std::string& name);

 private:
  struct Shared;
  std::unique_ptr<Shared> shared_;
};

}  // namespace mmvk::bench
