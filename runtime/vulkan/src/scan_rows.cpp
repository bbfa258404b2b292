#include "scan_rows.hpp"

#include <algorithm>
#include <cstddef>

#include "device_database.hpp"
#include "mmvk/search/search.hpp"

namespace mmvk::vulkan::detail {

namespace {

// The frames no scan evaluates for query p (the continuing frame, which the
// merges add with its bias, and its exclusion window: mmvk::is_candidate),
// (first, last - first) twice, (kNoFrame, 0) when empty.
std::array<std::uint32_t, 4> skipped_frames(const QueryGpu& p) {
  std::array<std::uint32_t, 4> ranges = {kNoFrame, 0, kNoFrame, 0};
  if (p.continuing_frame == kNoFrame) return ranges;
  ranges[0] = p.continuing_frame;
  if (p.window_clip == kNoFrame) return ranges;
  // Offsets inside the clip: b is the continuing frame, w the window; a row
  // at offset a is excluded when |a - b| <= w, or, in a looping clip, when
  // count - |a - b| <= w (the distance through the wrap).
  const std::uint32_t count = p.clip_count;
  const std::uint32_t b = p.continuing_frame - p.clip_first;
  const std::uint32_t w = p.exclusion_window;
  const std::uint32_t first = w >= b ? 0 : b - w;
  const std::uint32_t last = w >= count - 1 - b ? count - 1 : b + w;
  ranges[0] = p.clip_first + first;
  ranges[1] = last - first;
  if (p.clip_loop != 0) {
    if (w > b) {
      // a > b: a >= b + count - w, a suffix of the clip.
      const std::uint32_t suffix = w - b >= count ? 0 : count - (w - b);
      ranges[2] = p.clip_first + suffix;
      ranges[3] = count - 1 - suffix;
    } else if (w >= count - b) {
      // a < b: a <= b + w - count, a prefix of the clip.
      ranges[2] = p.clip_first;
      ranges[3] = std::min(w - (count - b), count - 1);
    }
  }
  return ranges;
}

}  // namespace

std::vector<std::uint32_t> scan_frame_list(const Database& database) {
  std::vector<std::uint32_t> frames;
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (scanned_by_brute_force(database.frame_flags()[f])) frames.push_back(f);
  }
  return frames;
}

std::vector<std::uint32_t> scan_rows_before(const Database& database) {
  std::vector<std::uint32_t> before(std::size_t{database.frame_count()} + 1, 0);
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    before[f + 1] = before[f] + (scanned_by_brute_force(database.frame_flags()[f]) ? 1 : 0);
  }
  return before;
}

std::uint32_t feature_row(std::span<const std::uint32_t> rows_before, std::uint32_t frame) {
  if (rows_before.empty()) return frame;
  const std::uint32_t below = rows_before[frame];
  if (rows_before[frame + 1] != below) return below;  // a scan row
  return rows_before.back() + (frame - below);
}

std::array<std::uint32_t, 4> skipped_scan_rows(std::span<const std::uint32_t> rows_before, const QueryGpu& p) {
  const std::array<std::uint32_t, 4> frames = skipped_frames(p);
  if (rows_before.empty()) return frames;
  std::array<std::uint32_t, 4> rows = {kNoFrame, 0, kNoFrame, 0};
  for (std::size_t r = 0; r < 2; ++r) {
    if (frames[2 * r] == kNoFrame) continue;
    // Scan rows [lo, hi) hold the frames [first, first + span].
    const std::uint32_t lo = rows_before[frames[2 * r]];
    const std::uint32_t hi = rows_before[std::size_t{frames[2 * r]} + frames[2 * r + 1] + 1];
    if (lo == hi) continue;
    rows[2 * r] = lo;
    rows[2 * r + 1] = hi - lo - 1;
  }
  return rows;
}

}  // namespace mmvk::vulkan::detail
