#include "box_scan.hpp"

#include <algorithm>
#include <limits>

namespace mmvk::peers {

namespace {

void fill_boxes(const Database& db, std::uint32_t frames_per_box, std::vector<float>& lo, std::vector<float>& hi) {
  const std::uint32_t dims = db.dims();
  const std::size_t boxes = (std::size_t{db.frame_count()} + frames_per_box - 1) / frames_per_box;
  lo.assign(boxes * dims, std::numeric_limits<float>::infinity());
  hi.assign(boxes * dims, -std::numeric_limits<float>::infinity());
  for (std::uint32_t f = 0; f < db.frame_count(); ++f) {
    const std::size_t box = f / frames_per_box;
    const std::span<const float> row = db.row(f);
    for (std::uint32_t d = 0; d < dims; ++d) {
      lo[box * dims + d] = std::min(lo[box * dims + d], row[d]);
      hi[box * dims + d] = std::max(hi[box * dims + d], row[d]);
    }
  }
}

}  // namespace

BoxScan::BoxScan(const Database& database) : PeerBackend(database, "box-scan"), channel_end_(channel_ends(database)) {
  fill_boxes(database, kSmallBoxFrames, small_.lo, small_.hi);
  fill_boxes(database, kLargeBoxFrames, large_.lo, large_.hi);
}

Result<std::unique_ptr<BoxScan>> BoxScan::create(const Database& database) {
  MMVK_TRY(check_plain_database(database, "box-scan"));
  return std::unique_ptr<BoxScan>(new BoxScan(database));
}

std::size_t BoxScan::index_bytes() const {
  return (small_.lo.size() + small_.hi.size() + large_.lo.size() + large_.hi.size()) * sizeof(float);
}

float BoxScan::bound(const Boxes& boxes, std::size_t box, const float* query) const {
  const std::size_t dims = database_.dims();
  const float* lo = &boxes.lo[box * dims];
  const float* hi = &boxes.hi[box * dims];
  float total = 0.0f;
  std::uint32_t d = 0;
  for (const std::uint32_t end : channel_end_) {
    float sum = 0.0f;
    for (; d < end; ++d) {
      // 0 inside the box, else the distance to its nearer face: never more
      // than |row - query| for a row of the box.
      const float gap = std::max({lo[d] - query[d], query[d] - hi[d], 0.0f});
      sum += gap * gap;
    }
    total += sum;
  }
  return total;
}

Status BoxScan::search(const QueryBatch& batch, std::uint32_t k, std::span<Match> out) {
  MMVK_TRY(check_plain_batch(database_, batch, k, out, "box-scan"));
  const std::uint32_t frames = database_.frame_count();
  const std::uint32_t dims = database_.dims();
  const std::size_t large_count = large_.lo.size() / dims;
  constexpr std::uint32_t kSmallPerLarge = kLargeBoxFrames / kSmallBoxFrames;
  TopK best(k);
  for (std::size_t q = 0; q < batch.size; ++q) {
    const float* query = &batch.features[q * dims];
    for (std::size_t large = 0; large < large_count; ++large) {
      // Skip when the bound reaches the k-th best: every frame here comes
      // after the held ones, so it would lose an equal-cost tie too.
      if (bound(large_, large, query) >= best.threshold()) continue;
      const std::size_t small_end = std::min<std::size_t>((large + 1) * kSmallPerLarge, small_.lo.size() / dims);
      for (std::size_t small = large * kSmallPerLarge; small < small_end; ++small) {
        if (bound(small_, small, query) >= best.threshold()) continue;
        const std::uint32_t first = static_cast<std::uint32_t>(small * kSmallBoxFrames);
        const std::uint32_t last = std::min(first + kSmallBoxFrames, frames);
        for (std::uint32_t f = first; f < last; ++f) best.offer(f, plain_cost(database_.row(f).data(), query, channel_end_));
        stats_.rows_evaluated += last - first;
      }
    }
    best.write(out.subspan(q * k, k));
  }
  stats_.queries += batch.size;
  return Status{};
}

}  // namespace mmvk::peers
