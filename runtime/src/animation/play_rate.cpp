// Play rate and stride scale (play_rate.hpp).
#include "play_rate.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace mmvk::detail {

std::vector<float> stride_speeds(const Database& database, float stride_window) {
  const AnimationData& animation = *database.animation();
  const float fps = database.fps();
  const auto half = std::int64_t(std::lround(0.5f * stride_window * fps));
  std::vector<float> speeds(database.frame_count(), 0.0f);
  std::vector<double> path;  // the root's path length from the clip's first frame
  for (const Clip& clip : database.clips()) {
    path.assign(clip.frame_count, 0.0);
    for (std::uint32_t i = 1; i < clip.frame_count; ++i) {
      const glm::vec3* root = animation.root_positions.data() + clip.first_frame + i;
      const glm::vec3 step = root[0] - root[-1];
      path[i] = path[i - 1] + std::hypot(double(step.x), double(step.z));
    }
    const auto last = std::int64_t(clip.frame_count) - 1;
    for (std::int64_t i = 0; i <= last; ++i) {
      const std::int64_t from = std::max<std::int64_t>(0, i - half), to = std::min(last, i + half);
      if (to == from) continue;  // a one-frame clip stands
      const double metres = path[std::size_t(to)] - path[std::size_t(from)];
      speeds[clip.first_frame + std::size_t(i)] = float(metres * fps / double(to - from));
    }
  }
  return speeds;
}

SpeedScale speed_scale(const ControllerParams& params, float stride_speed, float target_speed,
                       float commanded_speed) {
  SpeedScale scale;
  if (!(stride_speed >= kStandingSpeed)) {
    if (!(commanded_speed >= kStandingSpeed)) scale.stride_scale = 0.0f;
    return scale;
  }
  const float wanted = target_speed / stride_speed;
  scale.play_rate = std::clamp(wanted, params.min_play_rate, params.max_play_rate);
  scale.stride_scale = std::clamp(wanted / scale.play_rate, params.min_stride_scale, params.max_stride_scale);
  return scale;
}

Status check_speed_params(const ControllerParams& p) {
  const struct {
    const char *low_name, *high_name;
    float low, high;
  } bounds[] = {{"min_play_rate", "max_play_rate", p.min_play_rate, p.max_play_rate},
                {"min_stride_scale", "max_stride_scale", p.min_stride_scale, p.max_stride_scale}};
  for (const auto& b : bounds) {
    if (!std::isfinite(b.low) || !(b.low > 0.0f)) {
      return make_error(std::string("crowd controller: ") + b.low_name + " must be finite and > 0, got " +
                        std::to_string(b.low));
    }
    if (!std::isfinite(b.high)) {
      return make_error(std::string("crowd controller: ") + b.high_name + " must be finite, got " +
                        std::to_string(b.high));
    }
    if (b.low > b.high) {
      return make_error(std::string("crowd controller: ") + b.low_name + " (" + std::to_string(b.low) +
                        ") must not be above " + b.high_name + " (" + std::to_string(b.high) + ")");
    }
  }
  if (!std::isfinite(p.stride_window) || !(p.stride_window > 0.0f)) {
    return make_error("crowd controller: stride_window must be finite and > 0 (seconds), got " +
                      std::to_string(p.stride_window));
  }
  if (!std::isfinite(p.correction_speed_ratio) || !(p.correction_speed_ratio > 0.0f)) {
    return make_error("crowd controller: correction_speed_ratio must be finite and > 0, got " +
                      std::to_string(p.correction_speed_ratio));
  }
  if (!std::isfinite(p.min_correction_speed) || p.min_correction_speed < 0.0f) {
    return make_error("crowd controller: min_correction_speed must be finite and >= 0 (m/s), got " +
                      std::to_string(p.min_correction_speed));
  }
  return {};
}

}  // namespace mmvk::detail
