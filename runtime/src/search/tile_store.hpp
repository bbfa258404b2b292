// The data the tile kernels read: rows copied into 16-lane tiles and boxes
// packed 16 to a pack (tile_store.cpp). FastSearch keeps its tiles in frame
// order, ClusterSearch in cluster order; both build them here.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <vector>

#include "mmvk/database/database.hpp"
#include "search/tile_kernels.hpp"

namespace mmvk::detail {

// An array aligned to a cache line, so each 16-lane load touches one line
// (floats) or half of one (16-bit halves).
template <class T>
class AlignedArray {
 public:
  AlignedArray() = default;
  explicit AlignedArray(std::size_t count, T fill = T{})
      : data_(static_cast<T*>(::operator new[](std::max<std::size_t>(count, 1) * sizeof(T), std::align_val_t{64}))),
        size_(count) {
    std::fill(data_.get(), data_.get() + count, fill);
  }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  T& operator[](std::size_t i) { return data_.get()[i]; }
  T operator[](std::size_t i) const { return data_.get()[i]; }
  std::size_t size() const { return size_; }

 private:
  struct Free {
    void operator()(T* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<T[], Free> data_;
  std::size_t size_ = 0;
};
using AlignedFloats = AlignedArray<float>;

// One past each channel's last dim, in schema order.
std::vector<std::uint32_t> channel_ends(const Database& db);

// Rows in tiles of 16 lanes: lane `slot % 16` of tile `slot / 16` holds the
// row of slot_frames[slot]. Padding lanes (kNoFrame) hold zeros, multiplier
// 1 and bias 0; they and the rows with a kNeverCandidate flag are invalid
// lanes, which the kernels never report.
struct TileStore {
  std::uint32_t tiles = 0;
  std::uint32_t dims = 0;
  std::vector<std::uint32_t> channel_end;  // [channels]
  AlignedFloats features;                  // [tiles][dims][16]
  AlignedFloats multiplier;                // [tiles][16]
  AlignedFloats bias;                      // [tiles][16]
  std::vector<std::int32_t> lane_valid;    // [tiles][16]: -1 valid, 0 not

  // slot_frames.size() must be a multiple of 16.
  static TileStore build(const Database& db, std::span<const std::uint32_t> slot_frames);

  TileArrays arrays() const {
    return {features.data(), multiplier.data(), bias.data(), lane_valid.data(), channel_end.data(),
            static_cast<std::uint32_t>(channel_end.size()), dims};
  }
};

// The box of a set of rows (or of smaller boxes) and the minimum multiplier
// and bias over them.
struct BoxAccumulator {
  std::vector<float> lo, hi;
  float min_multiplier = 0.0f;
  float min_bias = 0.0f;
  bool empty = true;

  explicit BoxAccumulator(std::uint32_t dims) : lo(dims), hi(dims) {}
  void add(const float* lo_values, const float* hi_values, float multiplier, float bias);
  void add_row(std::span<const float> row, float multiplier, float bias) {
    add(row.data(), row.data(), multiplier, bias);
  }
};

// Boxes packed 16 to a pack, box b in lane b % 16 of pack b / 16. Boxes never
// set keep the zero box, multiplier 1 and bias 0.
struct BoxPacks {
  AlignedFloats lo, hi;                      // [packs][dims][16]
  AlignedFloats min_multiplier, min_bias;    // [packs][16]
  std::uint32_t dims = 0;

  BoxPacks() = default;
  BoxPacks(std::size_t packs, std::uint32_t dims);
  void set(std::size_t box, const float* lo_values, const float* hi_values, float multiplier, float bias);
  // Stores `box` unless it is empty.
  void set(std::size_t box, const BoxAccumulator& acc) {
    if (!acc.empty) set(box, acc.lo.data(), acc.hi.data(), acc.min_multiplier, acc.min_bias);
  }
  BoxArrays arrays(const std::vector<std::uint32_t>& channel_end) const {
    return {lo.data(), hi.data(), min_multiplier.data(), min_bias.data(), channel_end.data(),
            static_cast<std::uint32_t>(channel_end.size()), dims};
  }
};

// BoxPacks at half precision, in half the bytes: each lo rounded down and
// each hi rounded up (float_to_half_down / _up), so a half box holds the
// float box it came from and its bound (Kernels::half_box_bounds) stays a
// lower bound of its rows' costs. The minimum multipliers and biases stay
// floats.
struct HalfBoxPacks {
  AlignedArray<std::uint16_t> lo, hi;        // [packs][dims][16]
  AlignedFloats min_multiplier, min_bias;    // [packs][16]
  std::uint32_t dims = 0;

  HalfBoxPacks() = default;
  explicit HalfBoxPacks(BoxPacks&& boxes);
  HalfBoxArrays arrays(const std::vector<std::uint32_t>& channel_end) const {
    return {lo.data(), hi.data(), min_multiplier.data(), min_bias.data(), channel_end.data(),
            static_cast<std::uint32_t>(channel_end.size()), dims};
  }
};

}  // namespace mmvk::detail
