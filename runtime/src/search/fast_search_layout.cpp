#include <algorithm>
#include <cstring>

#include "search/fast_search_layout.hpp"

namespace mmvk {

namespace detail {

AlignedFloats::AlignedFloats(std::size_t count, float fill)
    : data_(static_cast<float*>(::operator new[](std::max<std::size_t>(count, 1) * sizeof(float), std::align_val_t{64}))),
      size_(count) {
  std::fill(data_.get(), data_.get() + count, fill);
}

}  // namespace detail

namespace {

constexpr std::uint32_t kLanes = detail::kLanes;

// Writes the box of `rows` (row-major pointers of dims floats, candidates
// only) into lane `lane` of a packed [dims][16] box array.
struct BoxAccumulator {
  std::vector<float> lo, hi;
  float min_multiplier = 0.0f;
  float min_bias = 0.0f;
  bool empty = true;

  explicit BoxAccumulator(std::uint32_t dims) : lo(dims), hi(dims) {}

  void add(const float* lo_values, const float* hi_values, float multiplier, float bias) {
    if (empty) {
      std::copy(lo_values, lo_values + lo.size(), lo.begin());
      std::copy(hi_values, hi_values + hi.size(), hi.begin());
      min_multiplier = multiplier;
      min_bias = bias;
      empty = false;
      return;
    }
    for (std::size_t d = 0; d < lo.size(); ++d) {
      lo[d] = std::min(lo[d], lo_values[d]);
      hi[d] = std::max(hi[d], hi_values[d]);
    }
    min_multiplier = std::min(min_multiplier, multiplier);
    min_bias = std::min(min_bias, bias);
  }

  // Empty boxes keep the zero box, multiplier 1 and bias 0; their blocks
  // are skipped by their summary and never bounded.
  void store(detail::AlignedFloats& lo_out, detail::AlignedFloats& hi_out, detail::AlignedFloats& mult_out,
             detail::AlignedFloats& bias_out, std::size_t pack, std::uint32_t lane) const {
    if (empty) return;
    const std::size_t dims = lo.size();
    for (std::size_t d = 0; d < dims; ++d) {
      lo_out[(pack * dims + d) * kLanes + lane] = lo[d];
      hi_out[(pack * dims + d) * kLanes + lane] = hi[d];
    }
    mult_out[pack * kLanes + lane] = min_multiplier;
    bias_out[pack * kLanes + lane] = min_bias;
  }
};

void merge_summary(detail::BlockSummary& into, const detail::BlockSummary& block) {
  if (!block.any_candidate) return;
  into.tag_intersection = into.any_candidate ? (into.tag_intersection & block.tag_intersection) : block.tag_intersection;
  into.tag_union |= block.tag_union;
  into.any_candidate = true;
}

}  // namespace

std::unique_ptr<FastSearch::Layout> FastSearch::Layout::build(const Database& db, bool baseline_kernels) {
  auto layout = std::make_unique<Layout>();
  Layout& l = *layout;
  l.kernels = detail::select_kernels(baseline_kernels);
  l.frames = db.frame_count();
  l.dims = db.dims();
  l.tiles = (l.frames + kLanes - 1) / kLanes;
  l.groups = (l.tiles + kFastGroupTiles - 1) / kFastGroupTiles;
  l.group_packs = (l.groups + kLanes - 1) / kLanes;
  std::uint32_t end = 0;
  for (const FeatureChannel& channel : db.schema().channels) {
    end += channel.dims();
    l.channel_end.push_back(end);
  }
  const std::size_t dims = l.dims;

  l.features = detail::AlignedFloats(std::size_t{l.tiles} * dims * kLanes);
  l.multiplier = detail::AlignedFloats(std::size_t{l.tiles} * kLanes, 1.0f);
  l.bias = detail::AlignedFloats(std::size_t{l.tiles} * kLanes);
  l.lane_valid.assign(std::size_t{l.tiles} * kLanes, 0);
  l.tile_summary.assign(l.tiles, {});
  l.group_summary.assign(l.groups, {});
  const std::size_t group_lanes = std::size_t{l.groups} * kLanes;
  const std::size_t pack_lanes = std::size_t{l.group_packs} * kLanes;
  l.tile_lo = detail::AlignedFloats(group_lanes * dims);
  l.tile_hi = detail::AlignedFloats(group_lanes * dims);
  l.tile_min_multiplier = detail::AlignedFloats(group_lanes, 1.0f);
  l.tile_min_bias = detail::AlignedFloats(group_lanes);
  l.group_lo = detail::AlignedFloats(pack_lanes * dims);
  l.group_hi = detail::AlignedFloats(pack_lanes * dims);
  l.group_min_multiplier = detail::AlignedFloats(pack_lanes, 1.0f);
  l.group_min_bias = detail::AlignedFloats(pack_lanes);

  constexpr std::uint32_t kNeverCandidate = kFrameDoNotUse | kFrameEdgeExcluded | kFrameBlockTransition;
  for (std::uint32_t f = 0; f < l.frames; ++f) {
    const std::size_t tile = f / kLanes;
    const std::size_t lane = f % kLanes;
    const std::span<const float> row = db.row(f);
    for (std::size_t d = 0; d < dims; ++d) l.features[(tile * dims + d) * kLanes + lane] = row[d];
    l.multiplier[tile * kLanes + lane] = db.frame_multiplier()[f];
    l.bias[tile * kLanes + lane] = db.frame_bias()[f];
    // Block-transition rows are candidates only as the continuing frame,
    // which the search evaluates on its own before the tiles.
    if ((db.frame_flags()[f] & kNeverCandidate) == 0) {
      l.lane_valid[tile * kLanes + lane] = -1;
      merge_summary(l.tile_summary[tile], {true, db.frame_tags()[f], db.frame_tags()[f]});
    }
  }

  for (std::uint32_t group = 0; group < l.groups; ++group) {
    BoxAccumulator group_box(l.dims);
    const std::uint32_t first_tile = group * kFastGroupTiles;
    const std::uint32_t last_tile = std::min(l.tiles, first_tile + kFastGroupTiles);
    for (std::uint32_t tile = first_tile; tile < last_tile; ++tile) {
      BoxAccumulator tile_box(l.dims);
      for (std::uint32_t lane = 0; lane < kLanes; ++lane) {
        if (l.lane_valid[std::size_t{tile} * kLanes + lane] == 0) continue;
        const std::span<const float> row = db.row(tile * kLanes + lane);
        tile_box.add(row.data(), row.data(), l.multiplier[tile * kLanes + lane], l.bias[tile * kLanes + lane]);
      }
      tile_box.store(l.tile_lo, l.tile_hi, l.tile_min_multiplier, l.tile_min_bias, group, tile - first_tile);
      if (!tile_box.empty) {
        group_box.add(tile_box.lo.data(), tile_box.hi.data(), tile_box.min_multiplier, tile_box.min_bias);
      }
      merge_summary(l.group_summary[group], l.tile_summary[tile]);
    }
    group_box.store(l.group_lo, l.group_hi, l.group_min_multiplier, l.group_min_bias, group / kLanes, group % kLanes);
  }
  return layout;
}

}  // namespace mmvk
