// libFuzzer target: pose-target JSON (`mmvk query --pose-targets`) against
// the generated walk's database. A target list that parses and builds into
// a query must also search: build_pose_query names a target too far from
// the data instead of leaving the search to fail on overflowing costs.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "mmvk/query/pose_query.hpp"
#include "mmvk/search/reference_search.hpp"
#include "walk_database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const mmvk::Database& db = mmvk::fuzz::walk_database();
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mmvk::Result<std::vector<mmvk::PoseTarget>> targets = mmvk::parse_pose_targets_json(text, "fuzz.json");
  if (!targets.ok()) return 0;
  mmvk::Result<mmvk::PoseQuery> query = mmvk::build_pose_query(db, *targets, "fuzz.json");
  if (!query.ok()) return 0;
  mmvk::ReferenceSearch search(db);
  mmvk::Match match;
  const mmvk::Status searched =
      search.search(mmvk::QueryBatch{query->features, std::span(&query->params, 1), 1}, 1, std::span(&match, 1));
  if (!searched.ok()) {
    std::fprintf(stderr, "a pose query that built does not search: %s\n", searched.message().c_str());
    std::abort();
  }
  return 0;
}
