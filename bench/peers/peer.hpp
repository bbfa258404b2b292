// What every peer of the benchmark suite is: a SearchBackend that answers
// plain nearest neighbour (squared L2 over the normalized features), so the
// suite times peers and mmvk's backends through one interface.
//
// Peers know nothing of mmvk's per-query constraints and per-clip costs, so
// they only accept a database in which every frame is a candidate with
// multiplier 1 and bias 0 (bench_data's suite_database), and batches with no
// params (every query a plain one). Under those conditions mmvk's cost
// (search.hpp) is exactly the squared L2 distance, accumulated per channel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::peers {

// The database, the name and the counters every peer keeps.
class PeerBackend : public SearchBackend {
 public:
  std::string_view name() const override { return name_; }
  // One thread; the FAISS peers say how many OpenMP threads they chose.
  std::string device() const override { return cpu_device_text(1); }
  const Database& database() const override { return database_; }
  SearchStats stats() const override { return stats_; }
  void reset_stats() override { stats_ = {}; }

  // Host bytes of the peer's own structures (copies of the rows, trees,
  // boxes, centroids), beyond the Database it was made from.
  virtual std::size_t index_bytes() const = 0;
  // True when the peer returns the reference's frames (box-scan); FAISS flat
  // is exact up to float near-ties and says false.
  virtual bool exact() const = 0;
  // The settings the peer chose for this machine and how (a sweep's
  // figures), for the suite's record; empty when it has none to choose.
  virtual std::string settings() const { return {}; }

 protected:
  // `database` must outlive the peer.
  PeerBackend(const Database& database, std::string name) : database_(database), name_(std::move(name)) {}

  const Database& database_;
  std::string name_;
  SearchStats stats_;
};

// Error naming `peer` unless every frame is a candidate (no flags) with
// multiplier 1 and bias 0.
Status check_plain_database(const Database& database, std::string_view peer);

// validate_search plus: no per-query params.
Status check_plain_batch(const Database& database, const QueryBatch& batch, std::uint32_t k, std::span<const Match> out,
                         std::string_view peer);

// Where each channel's dims end ([channels]), for plain_cost and box bounds.
std::vector<std::uint32_t> channel_ends(const Database& database);

// The reference's cost of `row` for `query` with default params on a plain
// database, in its accumulation order (a float sum per channel, then the
// channel sums in schema order), so a peer that uses it returns costs
// bit-identical to the reference. Both spans hold dims values.
float plain_cost(const float* row, const float* query, std::span<const std::uint32_t> channel_end);

// True when `other` is, by the reference's cost, within float rounding of
// the exact best match `best` for `query`: its cost exceeds best.cost by at
// most 1e-5 of ||q||^2 + ||x_best||^2, the scale at which FAISS's expansion
// ||q||^2 + ||x||^2 - 2 q.x rounds (a few hundred ulp of it). A method that
// returns such a frame instead of the reference's lost a float near-tie,
// not a neighbour.
bool is_float_near_tie(const Database& database, std::span<const float> query, const Match& best, std::uint32_t other);

// Keeps the best k (cost, frame) pairs seen so far, sorted by match_less.
class TopK {
 public:
  explicit TopK(std::uint32_t k) : k_(k) { best_.reserve(k + 1); }
  // The cost a new candidate must not exceed to enter (infinity until k
  // candidates are held).
  float threshold() const;
  void offer(std::uint32_t frame, float cost);
  // Writes the k slots (Match{} beyond the candidates held) and clears.
  void write(std::span<Match> out);

 private:
  std::uint32_t k_;
  std::vector<Match> best_;
};

}  // namespace mmvk::peers
