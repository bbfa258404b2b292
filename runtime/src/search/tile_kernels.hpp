// The vectorized inner loops of the CPU tile module, shared by FastSearch and
// ClusterSearch (tile_kernels.cpp): the costs of 16-row tiles and the lower
// bounds of 16-box packs. They are compiled once per instruction set and one
// set is picked at run time (select_kernels), never with -march=native, so
// the library stays portable for the applications that embed it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "mmvk/search/search.hpp"

namespace mmvk::detail {

inline constexpr std::uint32_t kLanes = 16;

// A lane whose cost passed the query's threshold (not yet checked against
// tags, the exclusion window or the exact (cost, frame) order).
struct LaneHit {
  std::uint32_t slot;   // tile * 16 + lane (the frame itself when tiles hold the frames in order)
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

// Boxes of 16 per pack: [pack][dims][16] lo and hi, [pack][16] minimum
// multiplier and bias.
struct BoxArrays {
  const float* lo;
  const float* hi;
  const float* min_multiplier;
  const float* min_bias;
  const std::uint32_t* channel_end;
  std::uint32_t channels;
  std::uint32_t dims;
};

// BoxArrays at half precision (HalfBoxPacks): lo rounded down and hi
// rounded up, so each box holds the float box it came from.
struct HalfBoxArrays {
  const std::uint16_t* lo;
  const std::uint16_t* hi;
  const float* min_multiplier;
  const float* min_bias;
  const std::uint32_t* channel_end;
  std::uint32_t channels;
  std::uint32_t dims;
};

// Tiles at half precision (half_tile_store.hpp): [tile][dims][16] IEEE
// binary16 features, and [tile] masks of the lanes that may be candidates
// (bit l: lane l).
struct HalfTileArrays {
  const std::uint16_t* features;
  const std::uint16_t* lane_mask;
  const std::uint32_t* channel_end;
  std::uint32_t channels;
  std::uint32_t dims;
};

// The kernels for one instruction set, chosen once at run time.
struct Kernels {
  // Evaluates the tiles tile_ids[0..count) for `query_count` queries (1, 2 or
  // 4), with the reference's per-row accumulation order (bit-identical
  // costs), and writes the lanes that pass to `hits` (capacity count * 16 *
  // query_count). Returns the number of hits.
  std::size_t (*evaluate_tiles)(const TileArrays& tiles, const KernelQuery* queries, std::uint32_t query_count,
                                const std::uint32_t* tile_ids, std::size_t count, LaneHit* hits);

  // Lower bounds of the boxes of packs [first_pack, first_pack + pack_count)
  // for one query, into out[pack_count * 16]: min_multiplier * sum_ch w_ch *
  // sum_d gap_d^2 + min_bias, gap_d the distance of q_d to [lo_d, hi_d]. No
  // bound exceeds the cost of a row inside its box; channels of weight 0 are
  // skipped.
  void (*box_bounds)(const BoxArrays& boxes, std::size_t first_pack, std::size_t pack_count, const float* query,
                     const float* weights, float* out);
  // box_bounds over boxes held as halves (ClusterSearch's tile and span
  // boxes): the same operations on each half widened to float. A half box
  // holds its float box, so its bound is at most the float box's and never
  // exceeds the cost of a row inside.
  void (*half_box_bounds)(const HalfBoxArrays& boxes, std::size_t first_pack, std::size_t pack_count,
                          const float* query, const float* weights, float* out);
  // ClusterSearch's first filter, for one query: distances[i * 16 + l] gets
  // lane l's distance over the half rows of tile tile_ids[i], sum_ch w_ch
  // sum_d (q_d - xh_d)^2 summed in the cost's order, and masks[i] the valid
  // lanes (bit l: lane l) whose distance is not above `limit` (a NaN
  // distance passes). No multiplier or bias: HalfFilterLimits folds them
  // into the limit.
  void (*half_filter)(const HalfTileArrays& tiles, const float* query, const float* weights,
                      const std::uint32_t* tile_ids, float limit, std::size_t count, std::uint16_t* masks,
                      float* distances);
  const char* name;  // "avx512f", "avx2" or "generic"
  // Queries per brute-force pass, which share each row load: 4 with
  // AVX-512's 32 registers of one tile each (1.2x faster than 2 on the
  // Bandai volume set) and with AVX2 (a tile is 2 of 16 registers; 4
  // queries ran 1.18x faster than 2 on Bandai-sized rows), 2 with SSE2 (a
  // tile is 4 registers).
  std::uint32_t brute_queries;
};

// The widest kernels this CPU runs, or the x86-64 baseline ones (tests use
// them to hold every kernel to the reference).
Kernels select_kernels(bool baseline);

// The kernels of one instruction set, or false when this CPU cannot run
// them.
bool select_kernels(CpuKernels set, Kernels& out);

}  // namespace mmvk::detail
