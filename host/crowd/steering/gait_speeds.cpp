#include "steering/gait_speeds.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mmvk/search/search.hpp"

namespace mmvk::crowd {

namespace {

constexpr float kMovingMps = 0.4f;    // below this a frame stands or shuffles
constexpr float kRunFromMps = 2.0f;   // the walk-run transition of adults
constexpr float kRunOverWalk = 1.25f; // a run this much faster than the walk separates from it
constexpr double kGaitShare = 0.05;   // a gait needs this share of moving frames

float median(std::vector<float> values) {
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
  return values[values.size() / 2];
}

// The bit of tag `name`, or 0 when the database has no such tag.
TagMask tag_bit(const Database& database, const char* name) {
  const auto& names = database.tag_names();
  for (std::size_t t = 0; t < names.size(); ++t) {
    if (names[t] == name) return TagMask{1} << t;
  }
  return 0;
}

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[200];
  std::snprintf(text, sizeof(text), pattern, a, b);
  return text;
}

}  // namespace

Result<GaitSpeeds> measure_gait_speeds(const Database& database) {
  const FeatureSchema& schema = database.schema();
  int channel = -1;
  float furthest = 0.0f;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& ch = schema.channels[c];
    if (ch.kind != ChannelKind::TrajectoryPosition || ch.offsets_seconds.empty()) continue;
    const float offset = *std::max_element(ch.offsets_seconds.begin(), ch.offsets_seconds.end());
    if (offset > furthest) furthest = offset, channel = int(c);
  }
  if (channel < 0) {
    return make_error("the database has no trajectory_position channel, so the crowd cannot steer it "
                      "(rebuild it with a schema that has one, e.g. the default schema)");
  }
  const FeatureChannel& ch = schema.channels[std::size_t(channel)];
  const std::size_t index = std::size_t(std::max_element(ch.offsets_seconds.begin(), ch.offsets_seconds.end()) -
                                        ch.offsets_seconds.begin());
  const std::uint32_t dx = schema.offset(std::size_t(channel)) + std::uint32_t(2 * index);
  const auto norm = database.normalization();
  const TagMask walk_tag = tag_bit(database, kWalkTag);
  const TagMask run_tag = tag_bit(database, kRunTag);
  // Moving frames, and those of each gait: by tag where the tag exists, else
  // by speed (and not tagged as the other gait).
  std::vector<float> moving, walk, run;
  moving.reserve(database.frame_count());
  const QueryParams any;
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (!is_candidate(database, f, any)) continue;
    const auto row = database.row(f);
    const float x = row[dx] * norm[dx].scale + norm[dx].offset;
    const float z = row[dx + 1] * norm[dx + 1].scale + norm[dx + 1].offset;
    const float speed = std::sqrt(x * x + z * z) / furthest;
    if (speed < kMovingMps) continue;
    moving.push_back(speed);
    const TagMask tags = database.frame_tags()[f];
    const bool walks = walk_tag ? (tags & walk_tag) != 0 : speed < kRunFromMps && (tags & run_tag) == 0;
    const bool runs = run_tag ? (tags & run_tag) != 0 : speed >= kRunFromMps && (tags & walk_tag) == 0;
    if (walks) walk.push_back(speed);
    if (runs) run.push_back(speed);
  }
  if (moving.empty()) return make_error("no frame of the database moves faster than 0.4 m/s: nothing to walk with");
  GaitSpeeds result;
  std::vector<float> sorted = moving;
  std::sort(sorted.begin(), sorted.end());
  result.max_mps = sorted[std::min(sorted.size() - 1, std::size_t(0.95 * double(sorted.size())))];
  const double walk_share = double(walk.size()) / double(moving.size());
  const double run_share = double(run.size()) / double(moving.size());
  if (walk_share >= kGaitShare) result.walk_mps = median(walk);
  const float run_mps = run.empty() ? 0.0f : median(run);
  if (run_share < kGaitShare) {
    result.no_run_reason =
        run_tag ? format("the frames tagged 'run' are %.1f%% of the moving frames (a gait needs %.0f%%)",
                         100.0 * run_share, 100.0 * kGaitShare)
                : format("no frame is tagged 'run' and %.1f%% of the moving frames reach 2 m/s (a run needs %.0f%%)",
                         100.0 * run_share, 100.0 * kGaitShare);
  } else if (run_mps < kRunFromMps || (result.walk_mps > 0.0f && run_mps < kRunOverWalk * result.walk_mps)) {
    result.no_run_reason = std::string(run_tag ? "the frames tagged 'run'" : "the frames at 2 m/s or more") +
                           format(" move at %.2f m/s (median), which does not separate from a walk (a run needs "
                                  "2 m/s and 1.25 x the walk's %.2f m/s)",
                                  double(run_mps), double(result.walk_mps));
  } else {
    result.run_mps = run_mps;
    result.has_run = true;
    result.tagged = walk_tag != 0 && run_tag != 0;
  }
  if (result.walk_mps == 0.0f) result.walk_mps = result.has_run ? std::min(1.3f, result.run_mps) : median(moving);
  result.max_mps = std::max({result.max_mps, result.walk_mps, result.run_mps});
  return result;
}

}  // namespace mmvk::crowd
