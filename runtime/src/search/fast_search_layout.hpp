// FastSearch's tiled copy of the database and its two levels of boxes
// (built once in fast_search_layout.cpp, read by fast_search.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "mmvk/search/fast_search.hpp"
#include "search/tile_store.hpp"

namespace mmvk {

namespace detail {

// Tag and flag summary of a block's rows that may be candidates (rows that
// are not do-not-use, edge-excluded or block-transition).
struct BlockSummary {
  bool any_candidate = false;
  TagMask tag_union = 0;
  TagMask tag_intersection = 0;
};

inline bool block_may_match(const BlockSummary& block, const QueryParams& params) {
  return block.any_candidate && (block.tag_union & params.require_all) == params.require_all &&
         (block.tag_intersection & params.exclude_any) == 0;
}

}  // namespace detail

struct FastSearch::Layout {
  std::uint32_t frames = 0;
  std::uint32_t dims = 0;
  std::uint32_t tiles = 0;        // ceil(frames / 16)
  std::uint32_t groups = 0;       // ceil(tiles / 16)
  std::uint32_t group_packs = 0;  // ceil(groups / 16)
  detail::Kernels kernels{};

  detail::TileStore rows;  // frame f in lane f % 16 of tile f / 16
  std::vector<detail::BlockSummary> tile_summary;   // [tiles]
  std::vector<detail::BlockSummary> group_summary;  // [groups]
  detail::BoxPacks tile_box_packs;   // one pack per group, one lane per tile of it
  detail::BoxPacks group_box_packs;  // [group_packs], one lane per group

  // `kernels`: from detail::select_kernels (create() checks the CPU runs them).
  static std::unique_ptr<Layout> build(const Database& database, const detail::Kernels& kernels);

  detail::TileArrays tile_arrays() const { return rows.arrays(); }
  detail::BoxArrays tile_boxes() const { return tile_box_packs.arrays(rows.channel_end); }
  detail::BoxArrays group_boxes() const { return group_box_packs.arrays(rows.channel_end); }
};

}  // namespace mmvk
