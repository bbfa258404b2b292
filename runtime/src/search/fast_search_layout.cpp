#include <algorithm>
#include <numeric>

#include "search/fast_search_layout.hpp"
#include "search/top_k.hpp"

namespace mmvk {

namespace {

constexpr std::uint32_t kLanes = detail::kLanes;

void merge_summary(detail::BlockSummary& into, const detail::BlockSummary& block) {
  if (!block.any_candidate) return;
  into.tag_intersection = into.any_candidate ? (into.tag_intersection & block.tag_intersection) : block.tag_intersection;
  into.tag_union |= block.tag_union;
  into.any_candidate = true;
}

}  // namespace

std::unique_ptr<FastSearch::Layout> FastSearch::Layout::build(const Database& db, const detail::Kernels& kernels) {
  auto layout = std::make_unique<Layout>();
  Layout& l = *layout;
  l.kernels = kernels;
  l.frames = db.frame_count();
  l.dims = db.dims();
  l.tiles = (l.frames + kLanes - 1) / kLanes;
  l.groups = (l.tiles + kFastGroupTiles - 1) / kFastGroupTiles;
  l.group_packs = (l.groups + kLanes - 1) / kLanes;

  std::vector<std::uint32_t> slot_frames(std::size_t{l.tiles} * kLanes, kNoFrame);
  std::iota(slot_frames.begin(), slot_frames.begin() + l.frames, 0u);
  l.rows = detail::TileStore::build(db, slot_frames);
  l.tile_summary.assign(l.tiles, {});
  l.group_summary.assign(l.groups, {});
  l.tile_box_packs = detail::BoxPacks(l.groups, l.dims);
  l.group_box_packs = detail::BoxPacks(l.group_packs, l.dims);

  // Summaries and boxes cover the rows that may be candidates (valid lanes).
  for (std::uint32_t f = 0; f < l.frames; ++f) {
    if (l.rows.lane_valid[f] == 0) continue;
    merge_summary(l.tile_summary[f / kLanes], {true, db.frame_tags()[f], db.frame_tags()[f]});
  }
  for (std::uint32_t group = 0; group < l.groups; ++group) {
    detail::BoxAccumulator group_box(l.dims);
    const std::uint32_t first_tile = group * kFastGroupTiles;
    const std::uint32_t last_tile = std::min(l.tiles, first_tile + kFastGroupTiles);
    for (std::uint32_t tile = first_tile; tile < last_tile; ++tile) {
      detail::BoxAccumulator tile_box(l.dims);
      for (std::uint32_t f = tile * kLanes; f < (tile + 1) * kLanes; ++f) {
        if (l.rows.lane_valid[f] == 0) continue;
        tile_box.add_row(db.row(f), l.rows.multiplier[f], l.rows.bias[f]);
      }
      // Group g's tile boxes fill pack g (kFastGroupTiles == 16 lanes).
      l.tile_box_packs.set(tile, tile_box);
      if (!tile_box.empty) {
        group_box.add(tile_box.lo.data(), tile_box.hi.data(), tile_box.min_multiplier, tile_box.min_bias);
      }
      merge_summary(l.group_summary[group], l.tile_summary[tile]);
    }
    l.group_box_packs.set(group, group_box);
  }
  return layout;
}

}  // namespace mmvk
