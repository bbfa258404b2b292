// A tiny fixed database (4 frames x 2 dims, one clip) for targets that need
// one to validate against; make_seeds trains the cluster table seed on it so
// that mutations get past the database-hash check.
#pragma once

#include <utility>

#include "mmvk/database/database.hpp"

namespace mmvk::fuzz {

inline const Database& fixed_database() {
  static const Database db = [] {
    DatabaseParts parts;
    FeatureChannel channel;
    channel.name = "c";
    channel.kind = ChannelKind::Custom;
    channel.custom_dims = 2;
    parts.schema.channels = {channel};
    parts.fps = 30.0f;
    parts.normalization.assign(2, DimNormalization{});
    Clip clip;
    clip.name = "clip";
    clip.frame_count = 4;
    parts.clips = {clip};
    parts.frame_flags.assign(4, 0);
    parts.features = {0, 0, 1, 0, 0, 1, 1, 1};
    return std::move(Database::create(std::move(parts))).value();
  }();
  return db;
}

}  // namespace mmvk::fuzz
