// Factories of the cluster-pruned CPU backend for the typed backend suites
// (backend_suite.hpp, backend_data_suite.hpp). Each trains a table per
// database with round(sqrt(frames)) clusters.
#pragma once

#include <cstdint>
#include <map>
#include <memory>

#include "mmvk/cluster_search.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::test {

template <std::uint32_t NProbe, bool Box = true, bool Radius = false>
struct ClusterFactory {
  // The table must outlive the backend: the factory owns both its pool and
  // the tables it trained, one per database (tests make many backends over
  // the same database; training dominates in sanitizer builds).
  ThreadPool pool{2};
  std::map<std::uint64_t, std::unique_ptr<ClusterTable>> tables;

  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    std::unique_ptr<ClusterTable>& table = tables[db.content_hash()];
    if (!table) {
      KMeansParams params;
      params.iterations = 10;  // exactness does not depend on the clustering's quality
      Result<ClusterTable> trained = train_cluster_table(db, params, pool);
      if (!trained.ok()) return trained.error();
      table = std::make_unique<ClusterTable>(std::move(trained).value());
    }
    ClusterSearchOptions options;
    options.nprobe = NProbe;
    options.box_bound = Box;
    options.radius_bound = Radius;
    Result<std::unique_ptr<ClusterSearch>> backend = ClusterSearch::create(db, *table, pool, options);
    if (!backend.ok()) return backend.error();
    return std::unique_ptr<SearchBackend>(std::move(backend).value());
  }
};

// Exact, and nprobe = all (which must give the exact results).
using ClusterExactFactory = ClusterFactory<0>;
using ClusterProbeAllFactory = ClusterFactory<0xFFFFFFFFu>;

}  // namespace mmvk::test
