// The brute-force scan's rows and where its features live. The scan visits
// the frames no flag excludes (scanned_by_brute_force()), ascending; in
// brute-force mode the device feature matrix holds those frames first, in
// scan order, then every other frame, ascending. The scan then reads a row's
// features at the row's own index, with no fetch of its frame first (10%
// faster on lavapipe, Bandai volume 417k, 2026-11-27), and looks a frame up
// only for the best rows it keeps. The host maps what a query names by frame
// (its continuing frame, the rows it skips) into those positions.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "search_layout.hpp"

namespace mmvk::vulkan::detail {

// The frames the brute-force scan visits, ascending.
std::vector<std::uint32_t> scan_frame_list(const Database& database);

// rows_before[f]: the scan rows whose frame is below f, for f in
// [0, frames] (frames + 1 entries; the last is the scan's row count): the
// host's O(1) map from frames to scan rows, for every query of every batch.
std::vector<std::uint32_t> scan_rows_before(const Database& database);

// The feature-matrix row of `frame` when the scan rows come first: its scan
// row, or the scan's row count + its rank among the other frames. With an
// empty table (the cluster modes, which upload no scan) it is the frame.
std::uint32_t feature_row(std::span<const std::uint32_t> rows_before, std::uint32_t frame);

// The two frame ranges the scans skip for query p (the continuing frame and
// its exclusion window), as scan-row ranges: (first, last - first) each,
// (kNoFrame, 0) when empty. With an empty table (the cluster modes, whose
// scans index rows by frame) they stay frame ranges.
std::array<std::uint32_t, 4> skipped_scan_rows(std::span<const std::uint32_t> rows_before, const QueryGpu& p);

}  // namespace mmvk::vulkan::detail
