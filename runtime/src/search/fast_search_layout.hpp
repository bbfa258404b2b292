// FastSearch's tiled copy of the database and its two levels of boxes
// (built once in fast_search_layout.cpp, read by fast_search.cpp).
#pragma once

#include <cstdint>
#include <memory>
#include <new>
#include <vector>

#include "search/fast_search_kernels.hpp"
#include "mmvk/fast_search.hpp"

namespace mmvk {

namespace detail {

// A zero-filled float array aligned to a cache line, so each 16-lane load
// touches one line.
class AlignedFloats {
 public:
  AlignedFloats() = default;
  explicit AlignedFloats(std::size_t count, float fill = 0.0f);
  float* data() { return data_.get(); }
  const float* data() const { return data_.get(); }
  float& operator[](std::size_t i) { return data_.get()[i]; }
  float operator[](std::size_t i) const { return data_.get()[i]; }
  std::size_t size() const { return size_; }

 private:
  struct Free {
    void operator()(float* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<float[], Free> data_;
  std::size_t size_ = 0;
};

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
  std::vector<std::uint32_t> channel_end;
  detail::Kernels kernels{};

  detail::AlignedFloats features;    // [tiles][dims][16]
  detail::AlignedFloats multiplier;  // [tiles][16]
  detail::AlignedFloats bias;        // [tiles][16]
  std::vector<std::int32_t> lane_valid;  // [tiles][16]
  std::vector<detail::BlockSummary> tile_summary;   // [tiles]
  std::vector<detail::BlockSummary> group_summary;  // [groups]

  // Tile boxes, packed by group: [groups][dims][16], [groups][16].
  detail::AlignedFloats tile_lo, tile_hi, tile_min_multiplier, tile_min_bias;
  // Group boxes, packed by 16 groups: [group_packs][dims][16], [group_packs][16].
  detail::AlignedFloats group_lo, group_hi, group_min_multiplier, group_min_bias;

  static std::unique_ptr<Layout> build(const Database& database, bool baseline_kernels);

  detail::TileArrays tile_arrays() const {
    return {features.data(), multiplier.data(), bias.data(), lane_valid.data(), channel_end.data(),
            static_cast<std::uint32_t>(channel_end.size()), dims};
  }
  detail::BoxArrays tile_boxes() const {
    return {tile_lo.data(), tile_hi.data(), tile_min_multiplier.data(), tile_min_bias.data(), channel_end.data(),
            static_cast<std::uint32_t>(channel_end.size()), dims};
  }
  detail::BoxArrays group_boxes() const {
    return {group_lo.data(), group_hi.data(), group_min_multiplier.data(), group_min_bias.data(),
            channel_end.data(), static_cast<std::uint32_t>(channel_end.size()), dims};
  }
};

}  // namespace mmvk
