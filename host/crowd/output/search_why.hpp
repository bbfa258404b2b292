// Why each search of a few characters chose its frame: the recorder keeps
// the query each of them searched with (its normalized features and
// QueryParams) and, when the run ends, explains the chosen and the
// continuing frame channel by channel with mmvk's explain_query(), the same
// code `mmvk query --explain` prints, into Recording::why.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "output/recording.hpp"

namespace mmvk::crowd {

class SearchWhyRecorder {
 public:
  // Explains the searches of the characters `agents` (ascending, unique,
  // each below `crowd_agents`).
  SearchWhyRecorder(const Database& database, std::span<const std::uint32_t> agents, std::size_t crowd_agents);

  // The batch the tick submitted: query i is character characters[i]'s.
  void submitted(std::span<const std::uint32_t> characters, const QueryBatch& batch);
  // Character b's search, index `search` in Recording::searches[b], applied
  // `chosen` (kNoFrame: no candidate); its query is the one submitted last.
  void applied(std::uint32_t b, std::size_t search, std::uint32_t chosen);

  // Explains every search kept into recording.why, with the channel and
  // clip names. Errors: those of explain_query (a query that no longer
  // fits the database).
  Status finish(Recording& recording, ThreadPool& pool) const;

 private:
  struct Kept {
    std::uint32_t agent = 0;
    std::size_t search = 0;
    std::uint32_t chosen = kNoFrame;
    QueryParams params;
    std::size_t row = 0;  // into queries_, [dims]
  };
  const Database& database_;
  // [crowd characters] each one's slot among the explained, or -1.
  std::vector<std::int32_t> slot_of_;
  // Per explained character (by slot), its query in flight: [slots x dims] and params.
  std::vector<float> pending_;
  std::vector<QueryParams> pending_params_;
  std::vector<Kept> kept_;
  std::vector<float> queries_;  // [kept x dims]
};

}  // namespace mmvk::crowd
