// BvhFile -> Motion: channel values become local translations (metres) and
// rotations (unit quaternions), in mmvk's Y-up frame.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/constants.hpp>

#include "mmvk/import/motion.hpp"

namespace mmvk {

int Skeleton::find(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

namespace {

Status validate_bvh(const BvhFile& file) {
  const std::string& where = file.source;
  if (file.joints.empty()) return make_error(where + ": no joints");
  if (!(file.frame_time > 0.0) || !std::isfinite(file.frame_time)) {
    return make_error(where + ": frame time must be positive, got " + std::to_string(file.frame_time));
  }
  if (const double fps = 1.0 / file.frame_time; !(fps >= kMinFps && fps <= kMaxFps)) {
    char text[200];
    std::snprintf(text, sizeof(text), ": Frame Time %g s is %g frames/s, outside the supported [%g, %g]",
                  file.frame_time, fps, double(kMinFps), double(kMaxFps));
    return make_error(where + text);
  }
  if (file.frame_count < 0 || file.channel_count < 0) return make_error(where + ": negative frame or channel count");
  int next_channel = 0;
  for (std::size_t j = 0; j < file.joints.size(); ++j) {
    const BvhJoint& joint = file.joints[j];
    if (joint.parent >= static_cast<int>(j) || joint.parent < -1) {
      return make_error(where + ": joint " + joint.name + " has parent " + std::to_string(joint.parent) +
                        "; parents must come before their children");
    }
    if (joint.first_channel != next_channel) {
      return make_error(where + ": joint " + joint.name + " channels start at column " +
                        std::to_string(joint.first_channel) + ", expected " + std::to_string(next_channel));
    }
    next_channel += static_cast<int>(joint.channels.size());
  }
  if (next_channel != file.channel_count) {
    return make_error(where + ": joints declare " + std::to_string(next_channel) + " channels, channel_count is " +
                      std::to_string(file.channel_count));
  }
  const std::size_t expected = static_cast<std::size_t>(file.frame_count) * static_cast<std::size_t>(file.channel_count);
  if (file.values.size() != expected) {
    return make_error(where + ": " + std::to_string(file.values.size()) + " channel values, expected " +
                      std::to_string(file.frame_count) + " frames x " + std::to_string(file.channel_count));
  }
  return {};
}

// 1/frame_time, snapped to the nearest integer rate when within 0.01%: files
// write 120 fps as ".0083333" or "0.00833333", which would otherwise give
// 120.0005 fps and resampling drift.
float fps_from_frame_time(double frame_time) {
  const double fps = 1.0 / frame_time;
  const double rounded = std::round(fps);
  return static_cast<float>(std::abs(fps - rounded) <= 1e-4 * fps ? rounded : fps);
}

glm::vec3 axis_of(BvhChannel channel) {
  switch (channel) {
    case BvhChannel::Xposition:
    case BvhChannel::Xrotation: return {1.0f, 0.0f, 0.0f};
    case BvhChannel::Yposition:
    case BvhChannel::Yrotation: return {0.0f, 1.0f, 0.0f};
    case BvhChannel::Zposition:
    case BvhChannel::Zrotation: return {0.0f, 0.0f, 1.0f};
  }
  return {0.0f, 0.0f, 0.0f};
}

bool is_position(BvhChannel channel) {
  return channel == BvhChannel::Xposition || channel == BvhChannel::Yposition || channel == BvhChannel::Zposition;
}

int position_component(BvhChannel channel) {
  return channel == BvhChannel::Xposition ? 0 : channel == BvhChannel::Yposition ? 1 : 2;
}

}  // namespace

float guess_metres_per_unit(const BvhFile& file) {
  // Tree diameter in file units: the longest path between two leaves (End
  // Sites included), each bone counting |OFFSET|. The root's own OFFSET is a
  // placement, not a bone. For a human this is about toe tip to finger tip,
  // roughly 1.1 to 1.3 times the body height; it does not depend on how the
  // rest pose is oriented (Bandai's bones lie along local X).
  const std::size_t n = file.joints.size();
  std::vector<double> down(n, 0.0);  // longest path from joint j down to a leaf
  double diameter = 0.0;
  for (std::size_t k = n; k-- > 0;) {
    const BvhJoint& joint = file.joints[k];
    if (joint.has_end_site) {
      const double tip = glm::length(glm::dvec3(joint.end_site_offset));
      diameter = std::max(diameter, down[k] + tip);
      down[k] = std::max(down[k], tip);
    }
    if (joint.parent >= 0) {
      const std::size_t p = static_cast<std::size_t>(joint.parent);
      const double through = down[k] + glm::length(glm::dvec3(joint.offset));
      diameter = std::max(diameter, down[p] + through);
      down[p] = std::max(down[p], through);
    }
  }
  // Pick the unit that makes the diameter closest, on a log scale, to 2.2 m
  // (the CMU, DAZ and Bandai adults measure 2.0 to 2.4 m). Neighbouring candidates differ by >= 2.2x, so the choice
  // tolerates +-45% of proportion or pose-of-rest variation.
  static constexpr float kCandidates[] = {0.01f, 0.0254f, 0.05644f, 1.0f};
  if (!(diameter > 0.0)) return 1.0f;
  float best = kCandidates[0];
  double best_error = 1e30;
  for (const float unit : kCandidates) {
    const double error = std::abs(std::log(diameter * unit / 2.2));
    if (error < best_error) {
      best_error = error;
      best = unit;
    }
  }
  return best;
}

Result<Motion> motion_from_bvh(const BvhFile& file, const ImportOptions& options) {
  MMVK_TRY(validate_bvh(file));
  if (!(options.metres_per_unit >= 0.0f) || !std::isfinite(options.metres_per_unit)) {
    return make_error(file.source + ": metres_per_unit must be >= 0 (0 = guess), got " +
                      std::to_string(options.metres_per_unit));
  }
  const float scale = options.metres_per_unit > 0.0f ? options.metres_per_unit : guess_metres_per_unit(file);
  // Z-up -> Y-up is a -90 degree turn about X: (x, y, z) -> (x, z, -y).
  const glm::quat to_y_up = options.up_axis == UpAxis::Z
                                ? glm::angleAxis(-glm::half_pi<float>(), glm::vec3(1.0f, 0.0f, 0.0f))
                                : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);

  Motion motion;
  const std::size_t joints = file.joints.size();
  motion.skeleton.names.reserve(joints);
  for (const BvhJoint& joint : file.joints) {
    motion.skeleton.names.push_back(joint.name);
    motion.skeleton.parents.push_back(joint.parent);
    glm::vec3 offset = joint.offset * scale;
    if (joint.parent < 0) offset = to_y_up * offset;
    motion.skeleton.rest_offsets.push_back(offset);
  }
  motion.fps = fps_from_frame_time(file.frame_time);
  motion.frame_count = static_cast<std::uint32_t>(file.frame_count);
  motion.local_positions.resize(motion.frame_count * joints);
  motion.local_rotations.resize(motion.frame_count * joints);

  const std::size_t columns = static_cast<std::size_t>(file.channel_count);
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    const float* row = file.values.data() + f * columns;
    for (std::size_t j = 0; j < joints; ++j) {
      const BvhJoint& joint = file.joints[j];
      // Position channels replace the OFFSET component by component (Bandai
      // and LAFAN1 write the full translation there; adding would double it).
      glm::vec3 position = joint.offset;
      glm::quat rotation(1.0f, 0.0f, 0.0f, 0.0f);
      const float* values = row + joint.first_channel;
      for (std::size_t c = 0; c < joint.channels.size(); ++c) {
        const BvhChannel channel = joint.channels[c];
        if (is_position(channel)) {
          position[position_component(channel)] = values[c];
        } else {
          // Intrinsic rotations in file order: "Zrotation Xrotation Yrotation"
          // is Rz * Rx * Ry applied to the child's vectors.
          rotation = rotation * glm::angleAxis(glm::radians(values[c]), axis_of(channel));
        }
      }
      position *= scale;
      if (joint.parent < 0) {
        position = to_y_up * position;
        rotation = to_y_up * rotation;
      }
      motion.local_positions[motion.index(f, j)] = position;
      motion.local_rotations[motion.index(f, j)] = glm::normalize(rotation);
    }
  }
  return motion;
}

}  // namespace mmvk
