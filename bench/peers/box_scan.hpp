// The two-level bounding-box scan of compact motion matching
// implementations, written from its description: the frames are cut into
// small boxes of 16 consecutive frames and large boxes of 64, each holding
// the per-dimension min and max of its rows. One query at a time, the scan
// walks the large boxes in frame order and keeps the best cost so far; a
// box whose lower bound (the squared distance from the query to the box) is
// not below the running best is skipped, else its small boxes are tested the
// same way and the rows of a surviving small box are evaluated.
//
// Exact: the bound is accumulated in plain_cost's order from per-dimension
// gaps no larger than any member's differences, and float rounding is
// monotone, so it never exceeds a member's cost; and boxes come in frame
// order, so a skipped box holding a frame of equal cost could only lose the
// tie. Returns the reference's frames and cost bits. One thread.
#pragma once

#include <memory>

#include "peer.hpp"

namespace mmvk::peers {

inline constexpr std::uint32_t kSmallBoxFrames = 16;
inline constexpr std::uint32_t kLargeBoxFrames = 64;

class BoxScan final : public PeerBackend {
 public:
  // `database` must outlive the backend and be plain (check_plain_database).
  static Result<std::unique_ptr<BoxScan>> create(const Database& database);

  Status search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) override;
  std::size_t index_bytes() const override;
  bool exact() const override { return true; }

 private:
  struct Boxes {
    std::vector<float> lo, hi;  // [boxes x dims]
  };
  explicit BoxScan(const Database& database);
  float bound(const Boxes& boxes, std::size_t box, const float* query) const;

  std::vector<std::uint32_t> channel_end_;
  Boxes small_, large_;
};

}  // namespace mmvk::peers
