#include "features/foot_contacts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "mmvk/import/character.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk::detail {

namespace {

int resolve(const Skeleton& skeleton, const std::string& bone) {
  Result<int> joint = find_bone(skeleton, bone);
  return joint.ok() ? *joint : -1;
}

// The floor_percentile of a joint's height over the clip.
float floor_height(std::span<const glm::vec3> positions, std::size_t joints, std::size_t joint, float percentile) {
  std::vector<float> heights;
  heights.reserve(positions.size() / joints);
  for (std::size_t i = joint; i < positions.size(); i += joints) heights.push_back(positions[i].y);
  const std::size_t k = static_cast<std::size_t>(std::clamp(percentile, 0.0f, 1.0f) * float(heights.size() - 1));
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k), heights.end());
  return heights[k];
}

float horizontal_distance(const glm::vec3& a, const glm::vec3& b) { return std::hypot(a.x - b.x, a.z - b.z); }

// Runs of `value` in `in` shorter than `frames` that touch neither end of the
// clip take the other value (gaps closed, or short contacts removed).
void drop_short_runs(std::vector<std::uint8_t>& in, std::uint8_t value, std::uint32_t frames) {
  const std::size_t n = in.size();
  for (std::size_t begin = 0; begin < n;) {
    std::size_t end = begin;
    while (end < n && in[end] == in[begin]) ++end;
    if (in[begin] == value && begin > 0 && end < n && end - begin < frames) {
      std::fill(in.begin() + std::ptrdiff_t(begin), in.begin() + std::ptrdiff_t(end), std::uint8_t(1 - value));
    }
    begin = end;
  }
}

// Frames in `seconds` at `fps`, so that a duration of exactly n frames
// counts as n (0.1 s at 30 fps is 3 frames, not 3.0000001).
std::uint32_t whole_frames(float seconds, float fps) {
  // Clamped before the conversion: a huge duration means longer than any clip.
  return static_cast<std::uint32_t>(std::clamp(std::ceil(seconds * fps - 1e-3f), 0.0f, 1e9f));
}

// One point's contact per frame (0/1): hysteresis, then the minimum durations.
std::vector<std::uint8_t> point_contacts(std::span<const glm::vec3> positions, std::size_t joints, std::size_t joint,
                                         std::uint32_t frames, float fps, float height_extra,
                                         const FootContactParams& params) {
  const float floor = params.height_above_clip_floor
                          ? floor_height(positions, joints, joint, params.floor_percentile)
                          : height_extra;
  auto at = [&](std::uint32_t f) { return positions[std::size_t{f} * joints + joint]; };
  std::vector<std::uint8_t> in(frames, 0);
  if (frames == 1) {
    in[0] = at(0).y - floor < params.enter_height ? 1 : 0;  // no motion to measure
    return in;
  }
  // Hysteresis on steps of speed_step_seconds (whole frames, at least one,
  // at most the clip): a step is in contact while its horizontal speed and
  // both ends' heights are under the thresholds, and a frame is in contact
  // when a step in contact covers it. Steps of a fixed duration keep the
  // labels of one motion the same at 30 or 120 fps: over a single 120 fps
  // frame, marker jitter reads as speed.
  const std::uint32_t step =
      static_cast<std::uint32_t>(std::clamp(std::round(params.speed_step_seconds * fps), 1.0f, float(frames - 1)));
  bool contact = false;
  for (std::uint32_t f = 0; f + step < frames; ++f) {
    const float speed = horizontal_distance(at(f + step), at(f)) * fps / float(step);
    const float height = std::max(at(f).y, at(f + step).y) - floor;
    contact = contact ? height < params.exit_height && speed < params.exit_speed
                      : height < params.enter_height && speed < params.enter_speed;
    if (contact) std::fill_n(in.begin() + std::ptrdiff_t(f), step + 1, std::uint8_t(1));
  }
  drop_short_runs(in, 0, whole_frames(params.min_gap_seconds, fps));
  drop_short_runs(in, 1, whole_frames(params.min_contact_seconds, fps));
  return in;
}

}  // namespace

ClipContacts detect_foot_contacts(const Skeleton& skeleton, std::span<const glm::vec3> positions,
                                  std::uint32_t frames, float fps, const FootContactParams& params) {
  ClipContacts out;
  out.bits.assign(frames, 0);
  out.toes = {resolve(skeleton, params.left_toe), resolve(skeleton, params.right_toe)};
  out.heels = {resolve(skeleton, params.left_heel), resolve(skeleton, params.right_heel)};
  if (frames == 0 || !out.resolved()) return out;
  const std::size_t joints = skeleton.size();
  const std::uint32_t min_gap = whole_frames(params.min_gap_seconds, fps);
  for (int s = 0; s < 2; ++s) {
    const std::size_t side = static_cast<std::size_t>(s);
    std::vector<std::uint8_t> toe(frames, 0);
    std::vector<std::uint8_t> heel(frames, 0);
    if (out.toes[side] >= 0) {
      toe = point_contacts(positions, joints, std::size_t(out.toes[side]), frames, fps, 0.0f, params);
    }
    if (out.heels[side] >= 0) {
      heel = point_contacts(positions, joints, std::size_t(out.heels[side]), frames, fps, params.heel_height_extra,
                            params);
    }
    // Close short gaps of the planted foot with the point planted before
    // the gap, so the foot locker holds one anchor across it.
    std::vector<std::uint8_t> planted(frames);
    for (std::uint32_t f = 0; f < frames; ++f) planted[f] = toe[f] | heel[f];
    std::vector<std::uint8_t> closed = planted;
    drop_short_runs(closed, 0, min_gap);
    for (std::uint32_t f = 1; f < frames; ++f) {
      if (closed[f] && !planted[f]) {
        toe[f] = toe[f - 1];
        heel[f] = heel[f - 1];
      }
    }
    for (std::uint32_t f = 0; f < frames; ++f) {
      if (toe[f]) out.bits[f] |= contact_toe_bit(s);
      if (heel[f]) out.bits[f] |= contact_heel_bit(s);
      if (toe[f] || heel[f]) out.bits[f] |= contact_planted_bit(s);
    }
  }
  return out;
}

}  // namespace mmvk::detail

namespace mmvk {

Status validate_foot_contact_params(const FootContactParams& params, const std::string& where) {
  std::string error;
  for_each_contact_bone(params, [&](const char* name, const std::string& bone) {
    if (error.empty() && bone.empty()) error = where + "." + name + ": empty bone name";
  });
  for_each_contact_number(params, [&](const char* name, float value) {
    if (error.empty() && (!std::isfinite(value) || value < 0.0f)) {
      error = where + "." + name + ": must be a finite number >= 0, got " + number_text(value);
    }
  });
  if (!error.empty()) return make_error(error);
  if (params.exit_height < params.enter_height) {
    return make_error(where + ".exit_height: must be >= enter_height (" + number_text(params.enter_height) +
                      "), got " + number_text(params.exit_height));
  }
  if (params.exit_speed < params.enter_speed) {
    return make_error(where + ".exit_speed: must be >= enter_speed (" + number_text(params.enter_speed) +
                      "), got " + number_text(params.exit_speed));
  }
  if (params.floor_percentile > 1.0f) {
    return make_error(where + ".floor_percentile: must be in [0, 1], got " + number_text(params.floor_percentile));
  }
  return {};
}

}  // namespace mmvk
