#include "suite_methods.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <utility>

#include "bench_data.hpp"
#include "mmvk/search/backends.hpp"
#include "peer.hpp"
#include "box_scan.hpp"
#if defined(MMVK_HAS_FAISS)
#include "faiss_peers.hpp"
#endif
#if defined(MMVK_HAS_NANOFLANN)
#include "pca_kdtree.hpp"
#endif
#if defined(MMVK_HAS_VULKAN)
#include "mmvk/vulkan/vulkan_search.hpp"
#endif
#include "suite_vulkan.hpp"

namespace mmvk::bench {

namespace fs = std::filesystem;

namespace {

constexpr std::uint32_t kProbes[] = {1, 4, 16, 64};
constexpr std::uint32_t kCandidates[] = {100, 300, 1000};

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// "nprobe16" with prefix "nprobe" -> 16; nullopt when `name` is not prefix
// followed by digits only.
std::optional<std::uint32_t> number_after(const std::string& name, std::string_view prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  std::uint32_t value = 0;
  for (std::size_t i = prefix.size(); i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return std::nullopt;
    value = value * 10 + static_cast<std::uint32_t>(name[i] - '0');
  }
  return value;
}

template <class T>
double vector_bytes(const std::vector<T>& v) {
  return double(v.size() * sizeof(T));
}

double cluster_table_bytes(const ClusterTable& t) {
  return vector_bytes(t.centroids) + vector_bytes(t.offsets) + vector_bytes(t.members) + vector_bytes(t.box_min) +
         vector_bytes(t.box_max) + vector_bytes(t.min_multiplier) + vector_bytes(t.min_bias) +
         vector_bytes(t.tag_union) + vector_bytes(t.flags_intersection) + vector_bytes(t.tag_intersection) +
         vector_bytes(t.channel_radius);
}

// Tiles of 16 rows (kFastTileRows) that hold every frame.
double tile_count(const Database& db) { return double((db.frame_count() + kFastTileRows - 1) / kFastTileRows); }

// FastSearch's and ClusterSearch's tiled copy (mmvk/search/fast_search.hpp): rows
// in tiles of 16, each tile with a min/max box, plus fast-box's group boxes
// of 256 rows. Computed from the documented layout, not measured.
double tiled_copy_bytes(const Database& db) {
  const double tiles = tile_count(db);
  const double groups = double((db.frame_count() + 255) / 256);
  return (tiles * kFastTileRows + 2.0 * tiles + 2.0 * groups) * db.dims() * sizeof(float);
}

}  // namespace

const std::vector<std::string>& suite_method_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {"reference", "fast-brute", "fast-box", "clusters"};
    for (const std::uint32_t p : kProbes) n.push_back("nprobe" + std::to_string(p));
#if defined(MMVK_HAS_VULKAN)
    n.push_back("vulkan-brute");
    n.push_back("vulkan-clusters");
    for (const std::uint32_t p : kProbes) n.push_back("vulkan-nprobe" + std::to_string(p));
#endif
#if defined(MMVK_HAS_FAISS)
    n.push_back("faiss-flat");
    n.push_back("faiss-flat-1q");
    for (const std::uint32_t p : kProbes) n.push_back("faiss-ivf" + std::to_string(p));
#endif
#if defined(MMVK_HAS_NANOFLANN)
    for (const std::uint32_t c : kCandidates) n.push_back("pca-kdtree" + std::to_string(c));
#endif
    n.push_back("box-scan");
    return n;
  }();
  return names;
}

struct SuiteMethodFactory::Shared {
  Shared(const Database& database, ThreadPool& threads, std::string cache_stem)
      : db(database), pool(threads), stem(std::move(cache_stem)) {}

  const Database& db;
  ThreadPool& pool;
  std::string stem;
  std::optional<ClusterTable> table;
  double table_s = 0.0;
#if defined(MMVK_HAS_FAISS)
  std::optional<peers::FaissIvfBuild> ivf;
#endif
#if defined(MMVK_HAS_NANOFLANN)
  std::shared_ptr<peers::PcaKdTreeIndex> pca;
  double pca_s = 0.0;
#endif

  fs::path cache(const std::string& extension) const { return bench_work_dir() / (stem + extension); }

  // k-means with the defaults (round(sqrt N) clusters), cached with the
  // seconds its training took beside it.
  Result<const ClusterTable*> cluster_table() {
    if (table) return &*table;
    const fs::path path = cache(".mmkc");
    const fs::path seconds = fs::path(path.string() + ".seconds");
    Result<ClusterTable> loaded = load_cluster_table(path);
    if (loaded && validate_cluster_table(*loaded, db).ok()) {
      std::ifstream(seconds) >> table_s;
    } else {
      const auto start = std::chrono::steady_clock::now();
      loaded = train_cluster_table(db, KMeansParams{}, pool);
      if (!loaded) return loaded.error();
      table_s = seconds_since(start);
      if (Status saved = save_cluster_table(*loaded, path); saved) std::ofstream(seconds) << table_s << "\n";
    }
    table = std::move(loaded.value());
    return &*table;
  }

  Result<SuiteMethod> make_registered(const std::string& backend, std::uint32_t nprobe) {
    const BackendEntry* entry = suite_backends().registry().find(backend);
    if (entry == nullptr) return make_error(backend + ": not in this build's registry");
    BackendSpec spec{.name = backend, .pool = &pool};
    spec.nprobe = nprobe;
    crowd::DeviceSearchLimits limits;
    limits.max_batch = 8192;
    SuiteMethod method;
    method.exact = !entry->uses_nprobe;
    if (entry->uses_cluster_table) {
      MMVK_ASSIGN_OR_RETURN(spec.clusters, cluster_table());
      method.build_s += table_s;
      method.index_bytes += cluster_table_bytes(*table);
    }
    const auto start = std::chrono::steady_clock::now();
    MMVK_ASSIGN_OR_RETURN(method.backend, suite_backends().make(spec, db, limits));
    method.build_s += seconds_since(start);
    note_vulkan_device(*method.backend);
    if (!crowd::HostBackends::on_cpu(backend)) {
      method.vulkan = as_vulkan_search(*method.backend);
      // What the backend allocated (VulkanSearch::device_bytes): the
      // database, a cluster mode's table and rows in cluster order, and
      // the slots' scratch, which the cluster modes size for the worst case.
      if (method.vulkan != nullptr) method.device_bytes = double(method.vulkan->device_bytes());
      method.index_bytes = 0.0;  // the table was uploaded, the host keeps none
    } else if (backend != "reference") {
      method.index_bytes += tiled_copy_bytes(db);
      // ClusterSearch keeps its rows at half precision (half_filter, on by
      // default) and its tile boxes too: 2 bytes a value instead of 4.
      if (entry->uses_cluster_table) {
        method.index_bytes -= (double(db.frame_count()) + 2.0 * tile_count(db)) * db.dims() * 2.0;
      }
    }
    return method;
  }

  Result<SuiteMethod> make_peer(const std::string& name) {
    SuiteMethod method;
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<peers::PeerBackend> peer;
    if (name == "box-scan") {
      MMVK_ASSIGN_OR_RETURN(peer, peers::BoxScan::create(db));
    }
#if defined(MMVK_HAS_FAISS)
    if (name == "faiss-flat" || name == "faiss-flat-1q") {
      MMVK_ASSIGN_OR_RETURN(peer, peers::make_faiss_flat(db, name == "faiss-flat-1q"));
    } else if (const auto probes = number_after(name, "faiss-ivf")) {
      if (!ivf) {
        MMVK_ASSIGN_OR_RETURN(ivf, peers::build_faiss_ivf(db, cache(".faiss-ivf")));
      }
      MMVK_ASSIGN_OR_RETURN(peer, peers::make_faiss_ivf(db, ivf->index, *probes));
      method.build_s = ivf->build_seconds;  // the training, not the cache load
    }
#endif
#if defined(MMVK_HAS_NANOFLANN)
    if (const auto candidates = number_after(name, "pca-kdtree")) {
      if (!pca) {
        const auto pca_start = std::chrono::steady_clock::now();
        MMVK_ASSIGN_OR_RETURN(pca, peers::build_pca_kdtree(db));
        pca_s = seconds_since(pca_start);
      }
      MMVK_ASSIGN_OR_RETURN(peer, peers::make_pca_kdtree(db, pca, *candidates));
      method.build_s = pca_s;
    }
#endif
    if (!peer) return make_error(name + ": no such method in this build");
    if (method.build_s == 0.0) method.build_s = seconds_since(start);
    method.exact = peer->exact();
    method.index_bytes = double(peer->index_bytes());
    method.settings = peer->settings();
    method.backend = std::move(peer);
    return method;
  }
};

SuiteMethodFactory::SuiteMethodFactory(const Database& database, ThreadPool& pool, std::string cache_stem)
    : shared_(std::make_unique<Shared>(database, pool, std::move(cache_stem))) {}

SuiteMethodFactory::~SuiteMethodFactory() = default;

Result<SuiteMethod> SuiteMethodFactory::make(const std::string& name) {
  static const std::pair<const char*, const char*> kRegistered[] = {{"reference", "reference"},
                                                                    {"fast-brute", "fast-brute"},
                                                                    {"fast-box", "fast-box"},
                                                                    {"clusters", "clusters"},
                                                                    {"vulkan-brute", "vulkan-brute"},
                                                                    {"vulkan-clusters", "vulkan-clusters"}};
  for (const auto& [cell, backend] : kRegistered) {
    if (name == cell) return shared_->make_registered(backend, 4);
  }
  if (const auto probes = number_after(name, "nprobe")) return shared_->make_registered("clusters-nprobe", *probes);
  if (const auto probes = number_after(name, "vulkan-nprobe")) return shared_->make_registered("vulkan-nprobe", *probes);
  return shared_->make_peer(name);
}

}  // namespace mmvk::bench
