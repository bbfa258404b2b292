#include "search/half_tile_store.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "search/half_float.hpp"
#include "search/top_k.hpp"

namespace mmvk::detail {

namespace {

constexpr float kFloatInf = std::numeric_limits<float>::infinity();

// A float >= v (+inf stays +inf, NaN stays NaN): float(v) is within 2^-24
// of |v| relatively, or 2^-150 absolutely below the normal range, and the
// added terms cover both.
float round_up(double v) { return static_cast<float>(v + std::fabs(v) * 0x1p-22 + 0x1p-149); }

}  // namespace

HalfTileStore HalfTileStore::build(const Database& db, std::span<const std::uint32_t> slot_frames,
                                   std::span<const std::uint32_t> block_offsets) {
  HalfTileStore h;
  h.tiles = static_cast<std::uint32_t>(slot_frames.size() / kLanes);
  h.dims = db.dims();
  h.channels = static_cast<std::uint32_t>(db.schema().channels.size());
  h.rounding = 2.0 * (double(h.dims) + double(h.channels) + 4.0) * 0x1p-24;
  const std::size_t dims = h.dims;
  const std::size_t blocks = block_offsets.size() - 1;
  h.features = AlignedArray<std::uint16_t>(std::size_t{h.tiles} * dims * kLanes);
  h.lane_mask.assign(h.tiles, 0);
  h.blocks.assign(blocks, Block{});
  for (std::size_t block = 0; block < blocks; ++block) {
    Block& stats = h.blocks[block];
    bool any_row = false;
    for (std::size_t tile = block_offsets[block]; tile < block_offsets[block + 1]; ++tile) {
      std::uint16_t* features = h.features.data() + tile * dims * kLanes;
      for (std::size_t lane = 0; lane < kLanes; ++lane) {
        const std::uint32_t f = slot_frames[tile * kLanes + lane];
        if (f == kNoFrame) continue;  // zeros, exactly representable
        if ((db.frame_flags()[f] & kNeverCandidate) == 0) h.lane_mask[tile] |= static_cast<std::uint16_t>(1u << lane);
        const float* row = db.row(f).data();
        double error = 0.0;
        for (std::size_t d = 0; d < dims; ++d) {
          const float x = row[d];
          std::uint16_t half = 0;
          if (std::fabs(x) <= kHalfMax) {  // false for NaN too
            half = float_to_half(x);
            // Exact in double: both are floats within a factor of two of
            // each other (or the half is 0).
            const double gap = double(x) - double(half_to_float(half));
            error += gap * gap;
          } else {
            error = std::numeric_limits<double>::infinity();
          }
          features[d * kLanes + lane] = half;
        }
        // The double sum and root err by far less than 2^-40 of themselves.
        stats.error = std::max(stats.error, round_up(std::sqrt(error) * (1.0 + 0x1p-40)));
        const float m = db.frame_multiplier()[f];
        const float b = db.frame_bias()[f];
        stats.min_multiplier = any_row ? std::min(stats.min_multiplier, m) : m;
        stats.max_multiplier = any_row ? std::max(stats.max_multiplier, m) : m;
        stats.min_bias = any_row ? std::min(stats.min_bias, b) : b;
        stats.max_bias = any_row ? std::max(stats.max_bias, b) : b;
        stats.max_abs_bias = std::max(stats.max_abs_bias, std::fabs(b));
        any_row = true;
      }
    }
  }
  return h;
}

std::size_t HalfTileStore::bytes() const {
  return (features.size() + lane_mask.size()) * sizeof(std::uint16_t) + blocks.size() * sizeof(Block);
}

HalfFilterLimits::HalfFilterLimits(const HalfTileStore& store, std::span<const std::uint32_t> channel_end,
                                   const float* weights)
    : store_(&store) {
  double weighted_dims = 0.0;
  double max_weight = 0.0;
  std::uint32_t d = 0;
  for (std::uint32_t c = 0; c < store.channels; ++c) {
    weighted_dims += double(weights[c]) * double(channel_end[c] - d);
    max_weight = std::max(max_weight, double(weights[c]));
    d = channel_end[c];
  }
  underflow_ = (weighted_dims + double(store.channels) + 1.0) * 0x1p-149;
  weight_root_ = std::sqrt(max_weight) * (1.0 + 0x1p-50);
}

// Why no lane the exact kernel reports fails the filter. u = 2^-24; every
// float operation rounds to nearest, fl(z) = z (1 + e) + a with |e| <= u and
// |a| <= 2^-150, a != 0 only for products below the normal range (sums of
// floats are exact there). Take a lane with multiplier m >= min_multiplier >
// 0 (validated), bias b >= min_bias, |b| <= max_abs_bias, row x, half row
// xh, and the kernel's float total T >= 0, reported: fl(fl(m T) + b) <= t.
//  1. With P = fl(m T): fl(P + b) >= P + b - u (P + |b|), so
//     P <= (t - b + u |b|) / (1 - u); and P >= m T (1 - u) - 2^-150. So
//     T <= L = ((t - min_bias + u max_abs_bias) / (1 - u) + 2^-150) /
//     (min_multiplier (1 - u)). L < 0: no row of the tile is reported.
//  2. T is at most n = dims + channels + 4 roundings deep per term (the
//     difference, its square, the channel's adds, the weight, the adds over
//     channels), all of non-negative values but the first, so with D^2 =
//     sum_c w_c sum_d (q_d - x_d)^2 in real numbers, T >= D^2 (1 - u)^n -
//     U, U = (sum_c w_c dims_c + channels + 1) 2^-149 covering the products
//     below the normal range; (1 - u)^-n and (1 + u)^n are <= 1 + g, g =
//     2 n u (`rounding`). So D <= sqrt((L + U)(1 + g)).
//  3. The weights make a semi-norm, so the triangle inequality gives H <= D
//     + R, H^2 = sum_c w_c sum_d (q_d - xh_d)^2 and R^2 = sum_c w_c sum_d
//     (x_d - xh_d)^2 <= max_c w_c error^2.
//  4. The filter's float distance S, the same computation on xh, is <= H^2
//     (1 + g) + U.
// So S <= (sqrt((L + U)(1 + g)) + R)^2 (1 + g) + U, the limit returned.
// It is computed in double (each step errs by 2^-53 of its value; the
// factor 1 + 2^-30 covers them) and rounded up to a float. A NaN distance
// passes the filter (the kernel tests !(S > limit)), so a row the filter
// cannot judge is evaluated exactly, as before.
float HalfFilterLimits::operator()(std::uint32_t block, float threshold) {
  if (!(threshold < kFloatInf)) return kFloatInf;
  if (block == block_ && threshold == threshold_) return limit_;
  block_ = block;
  threshold_ = threshold;
  const HalfTileStore::Block& b = store_->blocks[block];
  constexpr double u = 0x1p-24;
  const double numerator = (double(threshold) - double(b.min_bias) + u * double(b.max_abs_bias)) / (1.0 - u) + 0x1p-150;
  if (numerator < 0.0) {
    limit_ = -kFloatInf;
  } else {
    const double g = 1.0 + store_->rounding;
    const double d = std::sqrt((numerator / (double(b.min_multiplier) * (1.0 - u)) + underflow_) * g) +
                     weight_root_ * double(b.error);
    limit_ = round_up((d * d * g + underflow_) * (1.0 + 0x1p-30));
  }
  return limit_;
}

// The other direction, with the notation above: S >= H^2 (1 - u)^n - U, so
// H^2 <= (S + U)(1 + g); D <= H + R; T <= D^2 (1 + g) + U; P = fl(m T) <=
// max_multiplier T (1 + u) + 2^-150; and the cost fl(P + b) <= P + max_bias
// + u (P + max_abs_bias). Computed in double, with 2^-30 of the value and
// 2^-140 absolutely for the double rounding, then rounded up.
float HalfFilterLimits::upper(std::uint32_t block, float distance) const {
  const HalfTileStore::Block& b = store_->blocks[block];
  constexpr double u = 0x1p-24;
  const double g = 1.0 + store_->rounding;
  const double d = std::sqrt((double(distance) + underflow_) * g) + weight_root_ * double(b.error);
  const double p = double(b.max_multiplier) * (d * d * g + underflow_) * (1.0 + u) + 0x1p-150;
  const double cost = p + double(b.max_bias) + u * (p + double(b.max_abs_bias));
  return round_up(cost + std::fabs(cost) * 0x1p-30 + 0x1p-140);
}

}  // namespace mmvk::detail
