// The vectorized inner loops of FastSearch (fast_search_kernels.cpp). They
// are compiled once per instruction set (function multiversioning: the
// loader picks the widest the CPU has), never with -march=native, so the
// library stays portable for the applications that embed it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mmvk::detail {

inline constexpr std::uint32_t kLanes = 16;

// A lane whose cost passed the query's threshold (not yet checked against
// tags, the exclusion window or the exact (cost, frame) order).
struct LaneHit {
  std::uint32_t frame;
  float cost;
  std::uint32_t query;  // index into the kernel's query array
};

struct KernelQuery {
  const float* features;  // [dims], normalized
  const float* weights;   // [channels]
  float threshold;        // lanes with cost <= threshold are reported
};

// Tiles: [tile][dims][16] features, [tile][16] multiplier, bias and lane
// mask (-1 = the row may be a candidate, 0 = padding or never a candidate).
struct TileArrays {
  const float* features;
  const float* multiplier;
  const float* bias;
  const std::int32_t* lane_valid;
  const std::uint32_t* channel_end;  // [channels]: one past each channel's last dim
  std::uint32_t channels;
  std::uint32_t dims;
};

// Boxes of 16 blocks per pack: [pack][dims][16] lo and hi, [pack][16]
// minimum multiplier and bias.
struct BoxArrays {
  const float* lo;
  const float* hi;
  const float* min_multiplier;
  const float* min_bias;
  const std::uint32_t* channel_end;
  std::uint32_t channels;
  std::uint32_t dims;
};

// The kernels for one instruction set, chosen once at run time.
struct Kernels {
// Evaluates the tiles tile_ids[0..count) for `query_count` queries (1, 2 or
// 4), with the reference's per-row accumulation order, and writes the hits
// to `hits` (capacity count * 16 * query_count). Returns the number of hits.
  std::size_t (*evaluate_tiles)(const TileArrays& tiles, const KernelQuery* queries, std::uint32_t query_count,
                                const std::uint32_t* tile_ids, std::size_t count, LaneHit* hits);

// Lower bounds of the 16 boxes of pack `pack` for one query, into out[16].
  void (*box_bounds)(const BoxArrays& boxes, std::size_t pack, const float* query, const float* weights, float* out);
  const char* name;  // "avx512f", "avx2" or "generic"
};

// The widest kernels this CPU runs, or the baseline ones.
Kernels select_kernels(bool baseline);

}  // namespace mmvk::detail
