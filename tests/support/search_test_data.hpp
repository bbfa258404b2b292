// Synthetic databases, queries and params for search tests, and the
// bit-exact comparison of search results (used by backend_suite.hpp and
// the search semantics tests).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/search/reference_search.hpp"

#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"

namespace mmvk::test {

// ---------------------------------------------------------------------------
// Synthetic databases

struct SyntheticSpec {
  std::uint32_t frames = 3000;
  std::uint32_t clips = 12;
  std::uint64_t seed = 7;
  // Flags, tags, loops, multipliers and biases that vary by clip.
  bool constraints = false;
  // Channels as Custom channels of these dims (default: a 27-d layout like
  // the default schema's: 3+3+3+3+3+6+6 dims).
  std::vector<std::uint32_t> channel_dims = {3, 3, 3, 3, 3, 6, 6};
};

inline FeatureSchema synthetic_schema(const std::vector<std::uint32_t>& channel_dims) {
  FeatureSchema schema;
  for (std::size_t c = 0; c < channel_dims.size(); ++c) {
    FeatureChannel channel;
    channel.name = "channel" + std::to_string(c);
    channel.kind = ChannelKind::Custom;
    channel.custom_dims = channel_dims[c];
    schema.channels.push_back(channel);
  }
  return schema;
}

// Tag names of constrained synthetic databases.
inline constexpr TagMask kTagWalk = 1u << 0;
inline constexpr TagMask kTagRun = 1u << 1;
inline constexpr TagMask kTagIdle = 1u << 2;
inline constexpr TagMask kTagRare = 1u << 3;    // held by one short clip only
inline constexpr TagMask kTagUnused = 1u << 4;  // held by no frame

// Clips of random-walk features (so boxes over neighbouring frames are
// tight, as with motion), continuous values (so minima are unique). With
// constraints: clip c loops when c % 3 == 0; every clip's last 3 frames are
// edge-excluded unless it loops; frames 5..9 of each clip are do-not-use and
// 20..24 block-transition; tags, multipliers and biases vary by clip, and
// clip 1 (only 10 frames) alone holds kTagRare.
inline DatabaseParts synthetic_parts(const SyntheticSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  DatabaseParts parts;
  parts.schema = synthetic_schema(spec.channel_dims);
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  parts.normalization.assign(dims, DimNormalization{});
  parts.tag_names = {"walk", "run", "idle", "rare", "unused"};
  parts.frame_flags.assign(spec.frames, 0);
  parts.features.resize(std::size_t{spec.frames} * dims);
  std::vector<std::uint32_t> sizes(spec.clips, spec.frames / spec.clips);
  sizes.back() += spec.frames % spec.clips;
  if (spec.constraints && spec.clips > 2) {
    sizes[2] += sizes[1] - 10;  // clip 1 is short
    sizes[1] = 10;
  }
  std::uint32_t first = 0;
  for (std::uint32_t c = 0; c < spec.clips; ++c) {
    Clip clip;
    clip.name = "clip" + std::to_string(c);
    clip.first_frame = first;
    clip.frame_count = sizes[c];
    if (spec.constraints) {
      clip.loop = c % 3 == 0;
      clip.tags = c == 1 ? (kTagRare | kTagWalk) : (c % 2 == 0 ? kTagWalk : kTagRun) | (c % 4 == 3 ? kTagIdle : 0);
      clip.cost_multiplier = 0.5f + 1.5f * uniform(rng);
      clip.cost_bias = uniform(rng) - 0.5f;
      for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
        std::uint32_t& flags = parts.frame_flags[first + f];
        if (f >= 5 && f < 10 && c != 1) flags |= kFrameDoNotUse;
        if (f >= 20 && f < 25) flags |= kFrameBlockTransition;
        if (!clip.loop && f + 3 >= clip.frame_count && c != 1) flags |= kFrameEdgeExcluded;
      }
    }
    std::vector<float> value(dims);
    for (float& v : value) v = normal(rng);
    for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
      for (std::uint32_t d = 0; d < dims; ++d) {
        value[d] += 0.15f * normal(rng);
        parts.features[std::size_t{first + f} * dims + d] = value[d];
      }
    }
    parts.clips.push_back(clip);
    first += clip.frame_count;
  }
  return parts;
}

inline Database make_database(DatabaseParts parts) {
  Result<Database> db = Database::create(std::move(parts));
  if (!db.ok()) {
    ADD_FAILURE() << "synthetic database rejected: " << db.message();
    std::abort();  // the test cannot go on without its data
  }
  return std::move(db).value();
}

inline Database synthetic_database(const SyntheticSpec& spec) { return make_database(synthetic_parts(spec)); }

// Queries [count x dims]: a frame's features plus noise, or pure noise.
inline std::vector<float> synthetic_queries(const Database& db, std::size_t count, std::uint64_t seed,
                                            float noise = 0.3f) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::uniform_int_distribution<std::uint32_t> frame(0, db.frame_count() - 1);
  std::vector<float> queries(count * db.dims());
  for (std::size_t q = 0; q < count; ++q) {
    const bool near_frame = q % 4 != 3;
    const std::span<const float> row = db.row(frame(rng));
    for (std::uint32_t d = 0; d < db.dims(); ++d) {
      queries[q * db.dims() + d] = near_frame ? row[d] + noise * normal(rng) : 1.5f * normal(rng);
    }
  }
  return queries;
}

// Random per-query options exercising every rule: continuing frames with
// negative and positive biases, exclusion windows, tag masks, weights incl. 0.
inline std::vector<QueryParams> random_params(const Database& db, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::uint32_t> frame(0, db.frame_count() - 1);
  std::uniform_int_distribution<int> choice(0, 7);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<QueryParams> params(count);
  for (QueryParams& p : params) {
    if (choice(rng) < 5) {
      p.continuing_frame = frame(rng);
      p.continuing_bias = 4.0f * uniform(rng) - 2.0f;
      // From the frame rather than the generator, so the draws (and every
      // other test's data) stay as they were before the multiplier existed.
      const float multipliers[] = {1.0f, 0.5f, 0.8f, 1.25f, 0.0f, 1.0f};
      p.continuing_multiplier = multipliers[p.continuing_frame % 6];
      p.exclusion_window = choice(rng) < 4 ? choice(rng) * 3 : 0;
    }
    const int tags = choice(rng);
    if (tags == 1) p.require_all = kTagWalk;
    if (tags == 2) p.exclude_any = kTagRun;
    if (tags == 3) p.require_all = kTagIdle | kTagRun;
    if (tags == 4) p.require_all = kTagRare;
    for (std::size_t c = 0; c < db.schema().channels.size(); ++c) {
      const int w = choice(rng);
      p.channel_weights[c] = w == 0 ? 0.0f : (w == 1 ? 2.5f : (w == 2 ? 0.25f : 1.0f));
    }
  }
  return params;
}

// ---------------------------------------------------------------------------
// Running and comparing

inline std::string describe(const Match& m) {
  std::ostringstream out;
  if (m.frame == kNoFrame) {
    out << "none";
  } else {
    out.precision(9);
    out << m.frame << ":" << m.cost << " (0x" << std::hex << std::bit_cast<std::uint32_t>(m.cost) << ")";
  }
  return out.str();
}

inline std::string describe(const QueryParams& p) {
  std::ostringstream out;
  out << "continuing_frame=" << (p.continuing_frame == kNoFrame ? std::string("none") : std::to_string(p.continuing_frame))
      << " continuing_bias=" << p.continuing_bias << " continuing_multiplier=" << p.continuing_multiplier
      << " exclusion_window=" << p.exclusion_window
      << " require_all=" << p.require_all << " exclude_any=" << p.exclude_any;
  return out.str();
}

// Runs one search; fails the test on an error.
inline std::vector<Match> run_search(SearchBackend& backend, std::span<const float> features,
                                     std::span<const QueryParams> params, std::size_t count, std::uint32_t k) {
  std::vector<Match> out(count * k, Match{123u, -1.0f});  // garbage the backend must overwrite
  const Status status = backend.search(QueryBatch{features, params, count}, k, out);
  EXPECT_TRUE(status.ok()) << backend.name() << ": " << (status.ok() ? "" : status.message());
  return out;
}

// ReferenceSearch's results, memoized per test program: every backend
// instantiation of a suite compares against the same reference answers,
// which then cost one reference search instead of one per backend.
inline std::vector<Match> reference_results(const Database& db, std::span<const float> features,
                                            std::span<const QueryParams> params, std::size_t count, std::uint32_t k) {
  std::string key;
  auto add = [&key](const void* data, std::size_t size) { key.append(static_cast<const char*>(data), size); };
  const std::uint64_t hash = db.content_hash();
  add(&hash, sizeof(hash));
  add(&count, sizeof(count));
  add(&k, sizeof(k));
  add(features.data(), features.size_bytes());
  for (const QueryParams& p : params) {  // field by field: no padding bytes
    add(&p.continuing_frame, sizeof(p.continuing_frame));
    add(&p.continuing_bias, sizeof(p.continuing_bias));
    add(&p.continuing_multiplier, sizeof(p.continuing_multiplier));
    add(&p.exclusion_window, sizeof(p.exclusion_window));
    add(&p.require_all, sizeof(p.require_all));
    add(&p.exclude_any, sizeof(p.exclude_any));
    add(p.channel_weights.data(), sizeof(p.channel_weights));
  }
  static std::map<std::string, std::vector<Match>> cache;
  auto found = cache.find(key);
  if (found != cache.end()) return found->second;
  ReferenceSearch reference(db);
  std::vector<Match> out = run_search(reference, features, params, count, k);
  return cache.emplace(std::move(key), std::move(out)).first->second;
}

// The same frames and bit-identical costs, slot by slot.
inline void expect_identical(const std::vector<Match>& expected, const std::vector<Match>& actual, std::uint32_t k,
                             std::span<const QueryParams> params, std::string_view backend) {
  ASSERT_EQ(expected.size(), actual.size());
  int reported = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const bool same = expected[i].frame == actual[i].frame &&
                      std::bit_cast<std::uint32_t>(expected[i].cost) == std::bit_cast<std::uint32_t>(actual[i].cost);
    if (!same && reported++ < 8) {
      ADD_FAILURE() << backend << ": query " << i / k << " rank " << i % k << ": expected " << describe(expected[i])
                    << ", got " << describe(actual[i])
                    << (params.empty() ? std::string() : "; params: " + describe(params[i / k]));
    }
  }
}

}  // namespace mmvk::test
