// ClusterSearch's first filter: a half-precision copy of the row tiles
// (TileStore) and, per tile, what the rounding to half can hide, so that a
// lane's distance over the half rows gives a bound that never drops a row
// the exact kernel would report (half_tile_store.cpp proves it).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "search/tile_kernels.hpp"
#include "search/tile_store.hpp"

namespace mmvk::detail {

// The tiles of a TileStore at half precision, in the same slots, with what
// the rounding can hide per block of tiles (ClusterSearch: a cluster's
// tiles). A row value with no finite half (|x| > 65504, or not finite) is
// stored as 0 and makes its block's error +inf, so every lane of that block
// passes the filter.
struct HalfTileStore {
  std::uint32_t tiles = 0;
  std::uint32_t dims = 0;
  std::uint32_t channels = 0;
  AlignedArray<std::uint16_t> features;  // [tiles][dims][16]: IEEE binary16 bits, rounded to nearest
  // [tiles]: bit l set when lane l holds a row that may be a candidate (as
  // TileStore::lane_valid, 2 bytes a tile instead of 64).
  std::vector<std::uint16_t> lane_mask;
  // Per block, over its rows (padding left out): the largest
  // sqrt(sum_d (x_d - half(x_d))^2), rounded up, and the range of the
  // multipliers and biases (one struct: one cache line per visited block).
  struct Block {
    float error = 0.0f;
    float min_multiplier = 1.0f, max_multiplier = 1.0f;
    float min_bias = 0.0f, max_bias = 0.0f, max_abs_bias = 0.0f;
  };
  std::vector<Block> blocks;
  // Relative slack for the float rounding of one distance (see
  // HalfFilterLimits): 2 (dims + channels + 4) 2^-24.
  double rounding = 0.0;

  // The same slots as TileStore::build (slot_frames.size() a multiple of
  // 16); block b is tiles [block_offsets[b], block_offsets[b + 1]).
  static HalfTileStore build(const Database& db, std::span<const std::uint32_t> slot_frames,
                             std::span<const std::uint32_t> block_offsets);

  HalfTileArrays arrays(const std::uint32_t* channel_end) const {
    return {features.data(), lane_mask.data(), channel_end, channels, dims};
  }

  // Bytes held (for the docs' memory figures).
  std::size_t bytes() const;
};

// Bounds between a lane's half-precision distance (the kernels'
// half_filter) and its exact cost, per query: the largest distance a lane
// of a block can have when its cost is <= a threshold, and an upper bound
// of the cost of a lane of a given distance.
class HalfFilterLimits {
 public:
  HalfFilterLimits() = default;
  HalfFilterLimits(const HalfTileStore& store, std::span<const std::uint32_t> channel_end, const float* weights);
  // +inf when threshold is +inf or NaN; -inf when no row of the block can
  // cost <= threshold.
  // Keeps the last block's and threshold's limit.
  float operator()(std::uint32_t block, float threshold);
  // A float >= the lane's exact cost (the kernel's and the reference's);
  // NaN for a NaN distance.
  float upper(std::uint32_t block, float distance) const;

 private:
  const HalfTileStore* store_ = nullptr;
  double underflow_ = 0.0;     // (sum_c w_c dims_c + channels + 1) 2^-149
  double weight_root_ = 0.0;   // sqrt(max_c w_c), rounded up
  std::uint32_t block_ = 0xffffffffu;  // the last call's
  float threshold_ = 0.0f;
  float limit_ = 0.0f;
};

}  // namespace mmvk::detail
