// Factories of the cluster-pruned CPU backend for the typed backend suites
// (backend_suite.hpp, backend_data_suite.hpp), made through the backend
// registry. Each trains a table per database with round(sqrt(frames))
// clusters (cluster_table_cache.hpp).
#pragma once

#include <cstdint>
#include <memory>

#include "mmvk/search/backends.hpp"
#include "support/cluster_table_cache.hpp"

namespace mmvk::test {

// NProbe 0: exact ("clusters"); else "clusters-nprobe" with that nprobe.
template <std::uint32_t NProbe, bool Box = true>
struct ClusterFactory {
  // The cache owns the pool the backends run on and the tables.
  ClusterTableCache tables;

  Result<std::unique_ptr<SearchBackend>> make(const Database& db) {
    BackendSpec spec{.name = NProbe == 0 ? "clusters" : "clusters-nprobe", .pool = &tables.pool};
    MMVK_ASSIGN_OR_RETURN(spec.clusters, tables.table_for(db));
    spec.nprobe = NProbe;
    spec.cluster.box_bound = Box;
    return cpu_backends().make(spec, db);
  }
};

// Exact, and nprobe = all (which must give the exact results).
using ClusterExactFactory = ClusterFactory<0>;
using ClusterProbeAllFactory = ClusterFactory<0xFFFFFFFFu>;

}  // namespace mmvk::test
