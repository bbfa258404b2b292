#include "mmvk/search/backends.hpp"

#include <algorithm>
#include <utility>

#include "mmvk/search/reference_search.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {

namespace {

Result<ThreadPool*> spec_pool(const BackendSpec& spec) {
  if (spec.pool == nullptr) {
    return make_error("backend '" + spec.name + "' runs on threads: set BackendSpec::pool to a ThreadPool that outlives it");
  }
  return spec.pool;
}

Status check_nprobe(const BackendSpec& spec) {
  if (spec.nprobe == 0) return make_error("backend '" + spec.name + "': nprobe must be at least 1");
  return {};
}

template <class Backend>
Result<std::unique_ptr<SearchBackend>> as_backend(Result<std::unique_ptr<Backend>> made) {
  if (!made) return made.error();
  return std::unique_ptr<SearchBackend>(std::move(made).value());
}

Result<std::unique_ptr<SearchBackend>> make_fast(const BackendSpec& spec, const Database& database, bool prune) {
  MMVK_ASSIGN_OR_RETURN(ThreadPool* pool, spec_pool(spec));
  FastSearchOptions options = spec.fast;
  options.prune = prune;
  return as_backend(FastSearch::create(database, *pool, options));
}

Result<std::unique_ptr<SearchBackend>> make_clusters(const BackendSpec& spec, const Database& database, bool probe) {
  MMVK_ASSIGN_OR_RETURN(ThreadPool* pool, spec_pool(spec));
  if (probe) MMVK_TRY(check_nprobe(spec));
  std::optional<ClusterTable> trained;
  MMVK_ASSIGN_OR_RETURN(const ClusterTable* table, spec_cluster_table(spec, database, trained));
  ClusterSearchOptions options = spec.cluster;
  options.nprobe = probe ? spec.nprobe : 0;
  return as_backend(ClusterSearch::create(database, *table, *pool, options));
}

}  // namespace

Status BackendRegistry::add(BackendEntry entry) {
  if (entry.name.empty()) return make_error("backend registry: a backend needs a name");
  if (!entry.make) return make_error("backend registry: backend '" + entry.name + "' has no factory");
  if (find(entry.name) != nullptr) return make_error("backend registry: '" + entry.name + "' is already registered");
  entries_.push_back(std::move(entry));
  return {};
}

const BackendEntry* BackendRegistry::find(std::string_view name) const {
  for (const BackendEntry& entry : entries_) {
    if (entry.name == name) return &entry;
  }
  return nullptr;
}

std::string BackendRegistry::names() const {
  std::string text;
  for (const BackendEntry& entry : entries_) text += (text.empty() ? "" : ", ") + entry.name;
  return text;
}

std::string BackendRegistry::help(std::string_view indent) const {
  std::size_t width = 0;
  for (const BackendEntry& entry : entries_) width = std::max(width, entry.name.size());
  std::string text;
  for (const BackendEntry& entry : entries_) {
    text.append(indent).append(entry.name).append(width + 2 - entry.name.size(), ' ');
    text.append(entry.description).append("\n");
  }
  return text;
}

Result<std::unique_ptr<SearchBackend>> BackendRegistry::make(const BackendSpec& spec, const Database& database) const {
  const BackendEntry* entry = find(spec.name);
  if (entry == nullptr) return make_error("unknown backend '" + spec.name + "' (known: " + names() + ")");
  return entry->make(spec, database);
}

BackendRegistry cpu_backends() {
  BackendRegistry registry;
  // The names are fixed and distinct, so add() cannot fail here.
  (void)registry.add({"reference", "the CPU oracle: plain scalar brute force in the documented order",
                      [](const BackendSpec&, const Database& database) {
                        return as_backend(ReferenceSearch::create(database));
                      }});
  (void)registry.add({"fast-brute", "exact, every row, vectorized and threaded",
                      [](const BackendSpec& spec, const Database& database) { return make_fast(spec, database, false); }});
  (void)registry.add({"fast-box", "exact, rows pruned by tile and group bounding boxes",
                      [](const BackendSpec& spec, const Database& database) { return make_fast(spec, database, true); }});
  (void)registry.add({"clusters", "exact, rows pruned by k-means cluster bounds",
                      [](const BackendSpec& spec, const Database& database) {
                        return make_clusters(spec, database, false);
                      },
                      true});
  (void)registry.add({"clusters-nprobe", "approximate: the nprobe clusters with the nearest centroids",
                      [](const BackendSpec& spec, const Database& database) {
                        return make_clusters(spec, database, true);
                      },
                      true, true});
  return registry;
}

Result<std::unique_ptr<SearchBackend>> make_backend(const BackendSpec& spec, const Database& database) {
  return cpu_backends().make(spec, database);
}

Result<const ClusterTable*> spec_cluster_table(const BackendSpec& spec, const Database& database,
                                               std::optional<ClusterTable>& trained) {
  if (spec.clusters != nullptr) return spec.clusters;
  Result<ClusterTable> table = spec.pool != nullptr ? train_cluster_table(database, spec.kmeans, *spec.pool)
                                                    : train_cluster_table(database, spec.kmeans);
  if (!table) return make_error("backend '" + spec.name + "': training its cluster table: " + table.message());
  trained = std::move(table).value();
  return &*trained;
}

}  // namespace mmvk
