#include "gait_speeds.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mmvk/search.hpp"

namespace mmvk::crowd {

namespace {

constexpr float kMovingMps = 0.4f;    // below this a frame stands or shuffles
constexpr float kRunFromMps = 2.0f;   // the walk-run transition of adults
constexpr double kGaitShare = 0.05;   // a gait needs this share of moving frames

float median(std::vector<float>& values) {
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
  return values[values.size() / 2];
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
  std::vector<float> speeds;
  speeds.reserve(database.frame_count());
  const QueryParams any;
  for (std::uint32_t f = 0; f < database.frame_count(); ++f) {
    if (!is_candidate(database, f, any)) continue;
    const auto row = database.row(f);
    const float x = row[dx] * norm[dx].scale + norm[dx].offset;
    const float z = row[dx + 1] * norm[dx + 1].scale + norm[dx + 1].offset;
    speeds.push_back(std::sqrt(x * x + z * z) / furthest);
  }
  std::vector<float> walk, run, moving;
  for (float s : speeds) {
    if (s < kMovingMps) continue;
    moving.push_back(s);
    (s < kRunFromMps ? walk : run).push_back(s);
  }
  if (moving.empty()) return make_error("no frame of the database moves faster than 0.4 m/s: nothing to walk with");
  GaitSpeeds result;
  std::sort(moving.begin(), moving.end());
  result.max_mps = moving[std::min(moving.size() - 1, std::size_t(0.95 * double(moving.size())))];
  const double share = 1.0 / double(moving.size());
  if (double(walk.size()) * share >= kGaitShare) result.walk_mps = median(walk);
  if (double(run.size()) * share >= kGaitShare) {
    result.run_mps = median(run);
    result.has_run = true;
  }
  if (result.walk_mps == 0.0f) result.walk_mps = result.has_run ? std::min(1.3f, result.run_mps) : median(moving);
  if (!result.has_run) result.run_mps = result.walk_mps;
  result.max_mps = std::max({result.max_mps, result.walk_mps, result.run_mps});
  return result;
}

}  // namespace mmvk::crowd
