#include "search/tile_store.hpp"

#include <algorithm>
#include <utility>

#include "search/half_float.hpp"
#include "search/top_k.hpp"

namespace mmvk::detail {

std::vector<std::uint32_t> channel_ends(const Database& db) {
  std::vector<std::uint32_t> ends;
  std::uint32_t end = 0;
  for (const FeatureChannel& channel : db.schema().channels) {
    end += channel.dims();
    ends.push_back(end);
  }
  return ends;
}

TileStore TileStore::build(const Database& db, std::span<const std::uint32_t> slot_frames) {
  TileStore t;
  t.tiles = static_cast<std::uint32_t>(slot_frames.size() / kLanes);
  t.dims = db.dims();
  t.channel_end = channel_ends(db);
  const std::size_t dims = t.dims;
  t.features = AlignedFloats(std::size_t{t.tiles} * dims * kLanes);
  t.multiplier = AlignedFloats(std::size_t{t.tiles} * kLanes, 1.0f);
  t.bias = AlignedFloats(std::size_t{t.tiles} * kLanes);
  t.lane_valid.assign(std::size_t{t.tiles} * kLanes, 0);
  for (std::size_t slot = 0; slot < slot_frames.size(); ++slot) {
    const std::uint32_t f = slot_frames[slot];
    if (f == kNoFrame) continue;
    const std::size_t tile = slot / kLanes;
    const std::size_t lane = slot % kLanes;
    const std::span<const float> row = db.row(f);
    for (std::size_t d = 0; d < dims; ++d) t.features[(tile * dims + d) * kLanes + lane] = row[d];
    t.multiplier[slot] = db.frame_multiplier()[f];
    t.bias[slot] = db.frame_bias()[f];
    if ((db.frame_flags()[f] & kNeverCandidate) == 0) t.lane_valid[slot] = -1;
  }
  return t;
}

void BoxAccumulator::add(const float* lo_values, const float* hi_values, float multiplier, float bias) {
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

BoxPacks::BoxPacks(std::size_t packs, std::uint32_t box_dims)
    : lo(packs * box_dims * kLanes),
      hi(packs * box_dims * kLanes),
      min_multiplier(packs * kLanes, 1.0f),
      min_bias(packs * kLanes),
      dims(box_dims) {}

void BoxPacks::set(std::size_t box, const float* lo_values, const float* hi_values, float multiplier, float bias) {
  const std::size_t pack = box / kLanes;
  const std::size_t lane = box % kLanes;
  for (std::size_t d = 0; d < dims; ++d) {
    lo[(pack * dims + d) * kLanes + lane] = lo_values[d];
    hi[(pack * dims + d) * kLanes + lane] = hi_values[d];
  }
  min_multiplier[box] = multiplier;
  min_bias[box] = bias;
}

HalfBoxPacks::HalfBoxPacks(BoxPacks&& boxes)
    : lo(boxes.lo.size()),
      hi(boxes.hi.size()),
      min_multiplier(std::move(boxes.min_multiplier)),
      min_bias(std::move(boxes.min_bias)),
      dims(boxes.dims) {
  for (std::size_t i = 0; i < boxes.lo.size(); ++i) {
    lo[i] = float_to_half_down(boxes.lo[i]);
    hi[i] = float_to_half_up(boxes.hi[i]);
  }
}

}  // namespace mmvk::detail
