// Builds a two-frame database through the public API and searches it: proves
// the installed headers and libraries are complete and usable, the
// start-here header (mmvk/mmvk.hpp) with them.
#include <cstdio>

#include "mmvk/mmvk.hpp"
#include "mmvk/search/reference_search.hpp"

int main() {
  mmvk::DatabaseParts parts;
  mmvk::FeatureChannel channel;
  channel.name = "value";
  channel.kind = mmvk::ChannelKind::Custom;
  channel.custom_dims = 1;
  parts.schema.channels = {channel};
  parts.fps = 30.0f;
  parts.normalization = {mmvk::DimNormalization{}};
  parts.clips = {mmvk::Clip{.name = "clip", .frame_count = 2}};
  parts.frame_flags = {0, 0};
  parts.features = {0.0f, 1.0f};
  mmvk::Result<mmvk::Database> db = mmvk::Database::create(parts);
  if (!db) {
    std::fprintf(stderr, "%s\n", db.message().c_str());
    return 1;
  }
  mmvk::ReferenceSearch search(*db);
  const float query[] = {0.9f};
  mmvk::Match match;
  if (!search.search({.features = query, .params = {}, .size = 1}, 1, {&match, 1}).ok() || match.frame != 1) {
    std::fprintf(stderr, "unexpected search result\n");
    return 1;
  }
  std::printf("package consumer: ok (frame %u)\n", match.frame);
  return 0;
}
