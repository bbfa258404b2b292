// One trained cluster table per database for the test factories: tests make
// many backends over the same database, and training dominates in sanitizer
// builds. 10 Lloyd iterations: exactness does not depend on the clustering's
// quality. The tables live as long as the cache, so backends made from them
// may outlive the call that trained them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>

#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::test {

struct ClusterTableCache {
  ThreadPool pool{2};
  std::map<std::uint64_t, std::unique_ptr<ClusterTable>> tables;

  Result<const ClusterTable*> table_for(const Database& db) {
    std::unique_ptr<ClusterTable>& table = tables[db.content_hash()];
    if (!table) {
      KMeansParams params;
      params.iterations = 10;
      MMVK_ASSIGN_OR_RETURN(ClusterTable trained, train_cluster_table(db, params, pool));
      table = std::make_unique<ClusterTable>(std::move(trained));
    }
    return table.get();
  }
};

}  // namespace mmvk::test
