// Synthetic databases for the cluster-table tests and benchmarks: Gaussian
// blobs (so k-means has structure to find), clips with varied tags,
// multipliers, biases, loop flags and frame flags. Deterministic for a seed.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/database/database.hpp"
#include "mmvk/features/feature_schema.hpp"

namespace mmvk::test {

struct ClusteredDataSpec {
  std::uint32_t frames = 2000;
  std::vector<std::uint32_t> channel_dims = {3, 2, 4};  // Custom channels
  std::uint32_t blobs = 20;
  float blob_spread = 0.3f;   // std of the points around a blob centre
  float centre_range = 3.0f;  // blob centres uniform in [-range, range]
  std::uint32_t clip_frames = 97;
  bool varied_clips = true;   // tags, multipliers, biases, loops, flags; else plain clips
  std::uint64_t seed = 7;
};

inline double unit_uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

inline double normal(std::mt19937_64& rng) {
  // Box-Muller from our own uniforms (std distributions differ between libraries).
  const double u1 = 1.0 - unit_uniform(rng);
  const double u2 = unit_uniform(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

inline FeatureSchema custom_schema(const std::vector<std::uint32_t>& channel_dims) {
  FeatureSchema schema;
  for (std::size_t c = 0; c < channel_dims.size(); ++c) {
    FeatureChannel channel;
    channel.name = std::string("c").append(std::to_string(c));
    channel.kind = ChannelKind::Custom;
    channel.custom_dims = channel_dims[c];
    schema.channels.push_back(channel);
  }
  return schema;
}

// Parts of a clustered database; Database::create(parts) must succeed.
inline DatabaseParts clustered_parts(const ClusteredDataSpec& spec) {
  std::mt19937_64 rng(spec.seed);
  DatabaseParts parts;
  parts.schema = custom_schema(spec.channel_dims);
  parts.fps = 30.0f;
  const std::uint32_t dims = parts.schema.dims();
  parts.normalization.assign(dims, DimNormalization{});
  parts.tag_names = {"walk", "run", "idle", "crouch"};
  std::vector<float> centres(std::size_t{spec.blobs} * dims);
  for (float& v : centres) v = static_cast<float>((unit_uniform(rng) * 2.0 - 1.0) * spec.centre_range);
  parts.features.resize(std::size_t{spec.frames} * dims);
  // Each clip wanders near one blob, as motion clips stay in a region.
  std::uint32_t clip_index = 0;
  for (std::uint32_t first = 0; first < spec.frames; first += spec.clip_frames, ++clip_index) {
    Clip clip;
    clip.name = std::string("clip").append(std::to_string(clip_index));
    clip.first_frame = first;
    clip.frame_count = std::min(spec.clip_frames, spec.frames - first);
    if (spec.varied_clips) {
      clip.tags = rng() & 0xF;
      clip.loop = (rng() & 3) == 0;
      clip.cost_multiplier = 0.5f + static_cast<float>(unit_uniform(rng));
      clip.cost_bias = static_cast<float>(unit_uniform(rng) * 0.6 - 0.2);
    }
    const std::uint32_t blob = static_cast<std::uint32_t>(rng() % spec.blobs);
    for (std::uint32_t f = first; f < first + clip.frame_count; ++f) {
      for (std::uint32_t d = 0; d < dims; ++d) {
        parts.features[std::size_t{f} * dims + d] =
            centres[std::size_t{blob} * dims + d] + static_cast<float>(normal(rng)) * spec.blob_spread;
      }
      std::uint32_t flags = 0;
      if (spec.varied_clips) {
        const std::uint64_t r = rng() % 100;
        if (r < 3) flags |= kFrameDoNotUse;
        else if (r < 6) flags |= kFrameBlockTransition;
        else if (r < 8) flags |= kFrameEdgeExcluded;
      }
      parts.frame_flags.push_back(flags);
    }
    parts.clips.push_back(clip);
  }
  return parts;
}

// The database of clustered_parts(spec); a test failure if it is refused.
inline Database clustered_database(const ClusteredDataSpec& spec = {}) {
  Result<Database> db = Database::create(clustered_parts(spec));
  EXPECT_TRUE(db.ok()) << db.message();
  return std::move(db).value();
}

}  // namespace mmvk::test
