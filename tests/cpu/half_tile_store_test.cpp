// ClusterSearch's half precision, white-box: the half conversions (to
// nearest, and rounded down or up); the two bounds that keep the first
// filter exact (a row the exact kernel reports at a threshold is within
// HalfFilterLimits' limit, and HalfFilterLimits::upper is never below its
// cost), on rows with varied multipliers, biases, weights and values beyond
// the half range; the half boxes' bounds, never above a member's cost and
// close to the float boxes'; every kernel set's filter and box bounds give
// the generic ones' bits.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mmvk/search/search.hpp"
#include "search/half_float.hpp"
#include "search/half_tile_store.hpp"
#include "search/tile_kernels.hpp"
#include "search/tile_store.hpp"
#include "support/clustered_data.hpp"

namespace mmvk {
namespace {

TEST(HalfFloat, EveryFiniteHalfRoundTrips) {
  for (std::uint32_t h = 0; h < 0x10000; ++h) {
    const auto half = static_cast<std::uint16_t>(h);
    if ((half & 0x7c00u) == 0x7c00u) continue;  // inf and NaN are never stored
    const float f = detail::half_to_float(half);
    EXPECT_EQ(detail::float_to_half(f), half) << std::hex << h;
  }
}

// Round to nearest, ties to even, against the compiler's _Float16 where it
// has one; else against the two neighbouring halves.
TEST(HalfFloat, RoundsToNearestEven) {
  std::mt19937_64 rng(5);
  std::vector<float> values = {0.0f, -0.0f, 65504.0f, -65504.0f, 0x1p-24f, 0x1p-25f, 0x1.8p-24f, 0x1p-14f,
                               1.0f + 0x1p-11f, 1.0f + 0x1.8p-10f, 65519.0f, 0x1p-30f, 2049.0f, 2051.0f};
  for (int i = 0; i < 200000; ++i) {
    const float magnitude = std::ldexp(std::uniform_real_distribution<float>(1.0f, 2.0f)(rng),
                                       std::uniform_int_distribution<int>(-30, 15)(rng));
    values.push_back(rng() % 2 != 0 ? magnitude : -magnitude);
  }
  for (const float x : values) {
    if (std::fabs(x) > detail::kHalfMax) continue;
    const std::uint16_t h = detail::float_to_half(x);
#if defined(__FLT16_MAX__)
    EXPECT_EQ(h, std::bit_cast<std::uint16_t>(static_cast<_Float16>(x))) << x;
#endif
    // Nearest: no other half is closer.
    const double error = std::fabs(double(x) - double(detail::half_to_float(h)));
    for (const int step : {-1, 1}) {
      const auto neighbour = static_cast<std::uint16_t>(h + step);
      if ((neighbour & 0x7c00u) == 0x7c00u || ((neighbour ^ h) & 0x8000u) != 0) continue;
      EXPECT_LE(error, std::fabs(double(x) - double(detail::half_to_float(neighbour)))) << x;
    }
  }
}

// Every float between two neighbouring halves a < b rounds down to a and up
// to b; a half itself rounds to itself both ways; beyond the half range,
// down gives -inf or the largest half and up the smallest half or +inf.
TEST(HalfFloat, DirectedRoundingGivesTheNeighbouringHalves) {
  std::vector<float> halves;
  for (std::uint32_t h = 0; h < 0x10000; ++h) {
    const auto half = static_cast<std::uint16_t>(h);
    if ((half & 0x7c00u) != 0x7c00u && half != 0x8000u) halves.push_back(detail::half_to_float(half));  // one zero
  }
  std::sort(halves.begin(), halves.end());
  const auto down = [](float x) { return detail::half_to_float(detail::float_to_half_down(x)); };
  const auto up = [](float x) { return detail::half_to_float(detail::float_to_half_up(x)); };
  for (std::size_t i = 0; i + 1 < halves.size(); ++i) {
    const float a = halves[i];
    const float b = halves[i + 1];
    ASSERT_EQ(down(a), a);
    ASSERT_EQ(up(a), a);
    for (const float x : {std::nextafter(a, b), 0.5f * (a + b), std::nextafter(b, a)}) {
      ASSERT_EQ(down(x), a) << x;
      ASSERT_EQ(up(x), b) << x;
    }
  }
  EXPECT_EQ(down(-0.0f), 0.0f);
  EXPECT_EQ(up(-0.0f), 0.0f);
  const float inf = std::numeric_limits<float>::infinity();
  for (const float x : {65520.0f, 1.0e6f, inf}) {
    EXPECT_EQ(down(x), detail::kHalfMax) << x;
    EXPECT_EQ(up(x), inf) << x;
    EXPECT_EQ(down(-x), -inf) << x;
    EXPECT_EQ(up(-x), -detail::kHalfMax) << x;
  }
}

// The exact kernel's cost of one slot, with the generic kernels (the same
// bits as the reference's frame_cost).
struct Fixture {
  Database db;
  std::vector<std::uint32_t> slots;         // frames, padded to tiles
  std::vector<std::uint32_t> block_offsets;  // blocks of 3 tiles
  detail::TileStore rows;
  detail::HalfTileStore half;
};

Fixture make_fixture(bool beyond_half_range) {
  test::ClusteredDataSpec spec;
  spec.frames = 1500;
  DatabaseParts parts = test::clustered_parts(spec);
  std::mt19937_64 rng(17);
  const std::size_t frames = parts.frame_flags.size();
  parts.frame_multiplier.resize(frames);
  parts.frame_bias.resize(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    parts.frame_multiplier[f] = static_cast<float>(0.5 + 2.0 * test::unit_uniform(rng));
    parts.frame_bias[f] = static_cast<float>(2.0 * test::unit_uniform(rng) - 1.0);
  }
  if (beyond_half_range) parts.features[7 * std::size_t{parts.schema.dims()} + 2] = 1.0e6f;  // frame 7, tile 0
  Result<Database> db = Database::create(std::move(parts));
  EXPECT_TRUE(db.ok()) << db.message();
  Fixture x{std::move(db).value(), {}, {}, {}, {}};
  for (std::uint32_t f = 0; f < x.db.frame_count(); ++f) x.slots.push_back(f);
  while (x.slots.size() % detail::kLanes != 0) x.slots.push_back(kNoFrame);
  const auto tiles = static_cast<std::uint32_t>(x.slots.size() / detail::kLanes);
  for (std::uint32_t t = 0; t < tiles; t += 3) x.block_offsets.push_back(t);
  x.block_offsets.push_back(tiles);
  x.rows = detail::TileStore::build(x.db, x.slots);
  x.half = detail::HalfTileStore::build(x.db, x.slots, x.block_offsets);
  return x;
}

std::vector<float> random_query(const Database& db, std::mt19937_64& rng) {
  const auto row = db.row(static_cast<std::uint32_t>(rng() % db.frame_count()));
  std::vector<float> q(db.dims());
  for (std::uint32_t d = 0; d < db.dims(); ++d) q[d] = row[d] + static_cast<float>(0.3 * test::normal(rng));
  return q;
}

std::vector<float> random_weights(const Database& db, std::mt19937_64& rng) {
  std::vector<float> w(db.schema().channels.size());
  for (float& weight : w) weight = rng() % 4 == 0 ? 0.0f : static_cast<float>(0.01 + 30.0 * test::unit_uniform(rng));
  return w;
}

void check_bounds(bool beyond_half_range) {
  Fixture x = make_fixture(beyond_half_range);
  const detail::Kernels generic = detail::select_kernels(true);
  const detail::TileArrays tiles = x.rows.arrays();
  const detail::HalfTileArrays half_tiles = x.half.arrays(x.rows.channel_end.data());
  std::mt19937_64 rng(23);
  std::size_t checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::vector<float> q = random_query(x.db, rng);
    const std::vector<float> w = random_weights(x.db, rng);
    detail::HalfFilterLimits limits(x.half, x.rows.channel_end, w.data());
    for (std::uint32_t block = 0; block + 1 < x.block_offsets.size(); ++block) {
      for (std::uint32_t tile = x.block_offsets[block]; tile < x.block_offsets[block + 1]; ++tile) {
        // Every lane's exact cost (threshold +inf: all reported).
        const detail::KernelQuery query{q.data(), w.data(), std::numeric_limits<float>::infinity()};
        std::vector<detail::LaneHit> hits(detail::kLanes);
        const std::size_t count = generic.evaluate_tiles(tiles, &query, 1, &tile, 1, hits.data());
        std::uint16_t mask = 0;
        std::vector<float> distances(detail::kLanes);
        generic.half_filter(half_tiles, q.data(), w.data(), &tile, std::numeric_limits<float>::infinity(), 1, &mask,
                            distances.data());
        for (std::size_t h = 0; h < count; ++h) {
          const std::uint32_t lane = hits[h].slot % detail::kLanes;
          const float cost = hits[h].cost;
          const float distance = distances[lane];
          EXPECT_NE(mask & (1u << lane), 0u);
          // At its own cost as the threshold (the tightest at which the
          // exact kernel reports it) the lane passes the filter.
          const float limit = limits(block, cost);
          EXPECT_FALSE(distance > limit) << "tile " << tile << " lane " << lane << " cost " << cost << " distance "
                                         << distance << " limit " << limit;
          EXPECT_GE(limits.upper(block, distance), cost) << "tile " << tile << " lane " << lane;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 10000u);
  if (beyond_half_range) {
    // The tile with the value no half holds: every lane passes, at any
    // threshold.
    const std::vector<float> ones(x.db.schema().channels.size(), 1.0f);
    detail::HalfFilterLimits limits(x.half, x.rows.channel_end, ones.data());
    EXPECT_EQ(limits(0, -1.0e30f), -std::numeric_limits<float>::infinity());  // below every bias: nothing passes
    EXPECT_EQ(limits(0, 0.5f), std::numeric_limits<float>::infinity());
  }
}

TEST(HalfTileStore, TheBoundsHoldForEveryRow) { check_bounds(false); }

TEST(HalfTileStore, AValueBeyondTheHalfRangeLetsItsBlockPass) { check_bounds(true); }

// Calls check(kernels, q, w, rng) for 10 random queries and weights with
// each wider kernel set this CPU runs (AVX2, AVX-512).
template <class Check>
void for_each_wider_kernel_set(const Database& db, std::uint64_t seed, Check check) {
  std::mt19937_64 rng(seed);
  for (const CpuKernels set : {CpuKernels::Avx2, CpuKernels::Avx512}) {
    detail::Kernels kernels{};
    if (!detail::select_kernels(set, kernels)) continue;  // not run by this CPU
    for (int trial = 0; trial < 10; ++trial) {
      const std::vector<float> q = random_query(db, rng);
      const std::vector<float> w = random_weights(db, rng);
      check(kernels, q, w, rng);
    }
  }
}

TEST(HalfTileStore, EveryKernelSetFiltersAsTheGenericOne) {
  Fixture x = make_fixture(false);
  const detail::HalfTileArrays half_tiles = x.half.arrays(x.rows.channel_end.data());
  const detail::Kernels generic = detail::select_kernels(true);
  std::vector<std::uint32_t> ids(x.half.tiles);
  for (std::uint32_t t = 0; t < x.half.tiles; ++t) ids[t] = x.half.tiles - 1 - t;  // any order
  for_each_wider_kernel_set(x.db, 29, [&](const detail::Kernels& kernels, const std::vector<float>& q,
                                          const std::vector<float>& w, std::mt19937_64& rng) {
    const float limit = static_cast<float>(40.0 * test::unit_uniform(rng));
    // Counts that leave every remainder path (8, 4, 2, 1 tiles).
    for (const std::size_t count : {ids.size(), std::size_t{15}, std::size_t{1}}) {
      std::vector<std::uint16_t> masks(count), expected_masks(count);
      std::vector<float> distances(count * detail::kLanes), expected(count * detail::kLanes);
      generic.half_filter(half_tiles, q.data(), w.data(), ids.data(), limit, count, expected_masks.data(),
                          expected.data());
      kernels.half_filter(half_tiles, q.data(), w.data(), ids.data(), limit, count, masks.data(), distances.data());
      for (std::size_t i = 0; i < count; ++i) {
        ASSERT_EQ(masks[i], expected_masks[i]) << kernels.name << " tile " << ids[i];
        for (std::uint32_t lane = 0; lane < detail::kLanes; ++lane) {
          ASSERT_EQ(std::bit_cast<std::uint32_t>(distances[i * detail::kLanes + lane]),
                    std::bit_cast<std::uint32_t>(expected[i * detail::kLanes + lane]))
              << kernels.name << " tile " << ids[i] << " lane " << lane;
        }
      }
    }
  });
}

// The box of each tile's rows, with their minimum multiplier and bias.
detail::BoxPacks tile_boxes(const Fixture& x) {
  const std::size_t tiles = x.slots.size() / detail::kLanes;
  detail::BoxPacks boxes((tiles + detail::kLanes - 1) / detail::kLanes, x.db.dims());
  for (std::size_t tile = 0; tile < tiles; ++tile) {
    detail::BoxAccumulator box(x.db.dims());
    for (std::size_t slot = tile * detail::kLanes; slot < (tile + 1) * detail::kLanes; ++slot) {
      const std::uint32_t f = x.slots[slot];
      if (f != kNoFrame) box.add_row(x.db.row(f), x.db.frame_multiplier()[f], x.db.frame_bias()[f]);
    }
    boxes.set(tile, box);
  }
  return boxes;
}

// A half box holds its float box: its bound is at most the float box's and
// at most the cost of every row inside, and (within the half range) close to
// the float box's, so it prunes as the float box would.
void check_half_boxes(bool beyond_half_range) {
  Fixture x = make_fixture(beyond_half_range);
  const detail::Kernels generic = detail::select_kernels(true);
  const detail::BoxPacks float_boxes = tile_boxes(x);
  const detail::HalfBoxPacks half_boxes(tile_boxes(x));
  const detail::TileArrays tiles = x.rows.arrays();
  const std::size_t tile_count = x.slots.size() / detail::kLanes;
  const std::size_t packs = (tile_count + detail::kLanes - 1) / detail::kLanes;
  std::mt19937_64 rng(31);
  std::size_t rows_checked = 0;
  std::size_t close = 0;
  std::size_t far = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const std::vector<float> q = random_query(x.db, rng);
    const std::vector<float> w = random_weights(x.db, rng);
    std::vector<float> float_bound(packs * detail::kLanes), half_bound(packs * detail::kLanes);
    generic.box_bounds(float_boxes.arrays(x.rows.channel_end), 0, packs, q.data(), w.data(), float_bound.data());
    generic.half_box_bounds(half_boxes.arrays(x.rows.channel_end), 0, packs, q.data(), w.data(), half_bound.data());
    for (std::uint32_t tile = 0; tile < tile_count; ++tile) {
      ASSERT_LE(half_bound[tile], float_bound[tile]) << "tile " << tile;
      // Halves are 2^-11 apart relative to the value: far boxes widen by
      // about that share of their gap, near ones by a few thousandths.
      close += half_bound[tile] >= float_bound[tile] - (0.01f * std::fabs(float_bound[tile]) + 0.02f) ? 1u : 0u;
      far += float_bound[tile] > 1.0f ? 1u : 0u;
      const detail::KernelQuery query{q.data(), w.data(), std::numeric_limits<float>::infinity()};
      std::vector<detail::LaneHit> hits(detail::kLanes);
      const std::size_t count = generic.evaluate_tiles(tiles, &query, 1, &tile, 1, hits.data());
      for (std::size_t h = 0; h < count; ++h) {
        ASSERT_LE(half_bound[tile], hits[h].cost) << "tile " << tile << " slot " << hits[h].slot;
        ++rows_checked;
      }
    }
  }
  EXPECT_GT(rows_checked, 10000u);
  // A kernel that returned 0 or -inf would pass the checks above; most
  // bounds are far from 0, so it fails this one.
  EXPECT_GE(close, 40 * tile_count * 99 / 100);
  EXPECT_GE(far, 40 * tile_count / 2);
}

TEST(HalfBoxPacks, BoundsStayBelowEveryMemberAndNearTheFloatBoxes) { check_half_boxes(false); }

TEST(HalfBoxPacks, AValueBeyondTheHalfRangeKeepsTheBounds) { check_half_boxes(true); }

TEST(HalfBoxPacks, EveryKernelSetBoundsAsTheGenericOne) {
  Fixture x = make_fixture(false);
  const detail::HalfBoxPacks half_boxes(tile_boxes(x));
  const detail::HalfBoxArrays boxes = half_boxes.arrays(x.rows.channel_end);
  const std::size_t packs = half_boxes.min_bias.size() / detail::kLanes;
  const detail::Kernels generic = detail::select_kernels(true);
  for_each_wider_kernel_set(x.db, 37, [&](const detail::Kernels& kernels, const std::vector<float>& q,
                                          const std::vector<float>& w, std::mt19937_64&) {
    // Pack counts that leave every remainder path, from an odd first pack.
    for (const std::size_t count : {packs - 1, std::size_t{3}, std::size_t{1}}) {
      std::vector<float> bounds(count * detail::kLanes), expected(count * detail::kLanes);
      generic.half_box_bounds(boxes, 1, count, q.data(), w.data(), expected.data());
      kernels.half_box_bounds(boxes, 1, count, q.data(), w.data(), bounds.data());
      for (std::size_t i = 0; i < bounds.size(); ++i) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(bounds[i]), std::bit_cast<std::uint32_t>(expected[i]))
            << kernels.name << " box " << detail::kLanes + i;
      }
    }
  });
}

}  // namespace
}  // namespace mmvk
