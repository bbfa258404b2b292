#include "peer.hpp"

#include <algorithm>
#include <limits>
#include <string>

namespace mmvk::peers {

Status check_plain_database(const Database& database, std::string_view peer) {
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (database.frame_flags()[f] != 0 || database.frame_multiplier()[f] != 1.0f || database.frame_bias()[f] != 0.0f) {
      return make_error(std::string(peer) + ": frame " + std::to_string(f) +
                        " is not a plain candidate (flags, cost multiplier or bias): peers answer plain nearest "
                        "neighbour over a database where every frame is a candidate");
    }
  }
  return Status{};
}

Status check_plain_batch(const Database& database, const QueryBatch& batch, std::uint32_t k, std::span<const Match> out,
                         std::string_view peer) {
  MMVK_TRY(validate_search(database, batch, k, out));
  if (!batch.params.empty()) {
    return make_error(std::string(peer) + ": per-query params are not supported (plain nearest neighbour only)");
  }
  return Status{};
}

std::vector<std::uint32_t> channel_ends(const Database& database) {
  std::vector<std::uint32_t> ends;
  const FeatureSchema& schema = database.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) ends.push_back(schema.offset(c) + schema.channels[c].dims());
  return ends;
}

float plain_cost(const float* row, const float* query, std::span<const std::uint32_t> channel_end) {
  float total = 0.0f;
  std::uint32_t d = 0;
  for (const std::uint32_t end : channel_end) {
    float sum = 0.0f;
    for (; d < end; ++d) {
      const float diff = row[d] - query[d];
      sum += diff * diff;
    }
    // The reference adds weight * sum with weight 1.0f, then multiplier 1
    // times the total plus bias 0: both steps are exact, so they are left out.
    total += sum;
  }
  return total;
}

bool is_float_near_tie(const Database& database, std::span<const float> query, const Match& best, std::uint32_t other) {
  if (best.frame == kNoFrame || other >= database.frame_count()) return false;
  double scale = 0.0;
  const std::span<const float> row = database.row(best.frame);
  for (std::size_t d = 0; d < query.size(); ++d) scale += double(query[d]) * query[d] + double(row[d]) * row[d];
  return double(frame_cost(database, other, query, QueryParams{})) - best.cost <= 1e-5 * scale;
}

float TopK::threshold() const {
  return best_.size() < k_ ? std::numeric_limits<float>::infinity() : best_.back().cost;
}

void TopK::offer(std::uint32_t frame, float cost) {
  const Match candidate{frame, cost};
  if (best_.size() == k_ && !match_less(candidate, best_.back())) return;
  best_.insert(std::upper_bound(best_.begin(), best_.end(), candidate, match_less), candidate);
  if (best_.size() > k_) best_.pop_back();
}

void TopK::write(std::span<Match> out) {
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = i < best_.size() ? best_[i] : Match{};
  best_.clear();
}

}  // namespace mmvk::peers
