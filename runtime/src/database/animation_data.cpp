// Validation and sizes of the animation section (animation_data.hpp).
#include "mmvk/database/animation_data.hpp"

#include <cmath>
#include <string>

namespace mmvk {

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

std::size_t AnimationData::bytes_per_frame_in_memory() const {
  return joint_count() * sizeof(glm::quat) + translated_joints.size() * sizeof(glm::vec3) + sizeof(glm::vec3) +
         sizeof(float) + sizeof(std::uint8_t);
}

std::size_t AnimationData::bytes_per_frame_in_file() const {
  const std::size_t rotation = encoding == RotationEncoding::Float32 ? 16 : 8;
  // Root positions are stored as (x, z): y is 0 by construction.
  return joint_count() * rotation + translated_joints.size() * 12 + 8 + 4 + 1;
}

Status AnimationData::validate(std::uint32_t frames) const {
  const std::string where = "animation: ";
  const std::size_t joints = joint_count();
  if (joints == 0) return make_error(where + "the skeleton has no joints");
  if (skeleton.parents.size() != joints || skeleton.rest_offsets.size() != joints) {
    return make_error(where + "skeleton names, parents and rest offsets differ in size");
  }
  if (mirror_pairs.size() != joints) return make_error(where + "mirror_pairs has the wrong size");
  for (std::size_t j = 0; j < joints; ++j) {
    const int parent = skeleton.parents[j];
    if (parent >= static_cast<int>(j) || parent < -1) {
      return make_error(where + "joint " + std::to_string(j) + " ('" + skeleton.names[j] + "') has parent " +
                        std::to_string(parent) + " (parents must precede their children)");
    }
    const int pair = mirror_pairs[j];
    if (pair < 0 || static_cast<std::size_t>(pair) >= joints || mirror_pairs[static_cast<std::size_t>(pair)] != int(j)) {
      return make_error(where + "mirror pair of joint " + std::to_string(j) + " is not mutual");
    }
    if (!finite(skeleton.rest_offsets[j])) return make_error(where + "rest offset of joint " + std::to_string(j) + " is not finite");
  }
  for (std::size_t i = 0; i < translated_joints.size(); ++i) {
    if (translated_joints[i] >= joints || (i > 0 && translated_joints[i] <= translated_joints[i - 1])) {
      return make_error(where + "translated_joints must be ascending joint indices");
    }
  }
  for (std::size_t s = 0; s < 2; ++s) {
    for (int c : {contact_joints[s], heel_joints[s]}) {
      if (c < -1 || c >= static_cast<int>(joints)) return make_error(where + "contact joint out of range");
    }
  }
  if (frame_count != frames) {
    return make_error(where + std::to_string(frame_count) + " frames, the database has " + std::to_string(frames));
  }
  const std::size_t n = frame_count;
  if (local_rotations.size() != n * joints) return make_error(where + "local_rotations is not frames x joints");
  if (local_translations.size() != n * translated_joints.size()) {
    return make_error(where + "local_translations is not frames x translated joints");
  }
  if (root_positions.size() != n || root_yaws.size() != n || contacts.size() != n) {
    return make_error(where + "root_positions, root_yaws and contacts must have one value per frame");
  }
  for (std::size_t i = 0; i < local_rotations.size(); ++i) {
    const glm::quat& q = local_rotations[i];
    const float norm2 = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
    if (!std::isfinite(norm2) || std::abs(norm2 - 1.0f) > 1e-3f) {
      return make_error(where + "rotation of joint " + std::to_string(i % joints) + " on frame " +
                        std::to_string(i / joints) + " is not a unit quaternion");
    }
  }
  for (std::size_t i = 0; i < local_translations.size(); ++i) {
    if (!finite(local_translations[i])) return make_error(where + "a local translation is not finite");
  }
  for (std::size_t f = 0; f < n; ++f) {
    if (!finite(root_positions[f]) || !std::isfinite(root_yaws[f])) {
      return make_error(where + "root of frame " + std::to_string(f) + " is not finite");
    }
    if ((contacts[f] & ~kContactAllBits) != 0) {
      return make_error(where + "frame " + std::to_string(f) + " has unknown contact bits");
    }
    // A point on the ground means the foot is planted. The converse is not
    // required: a planted bit alone (contacts made in code) is allowed.
    for (int side = 0; side < 2; ++side) {
      const bool point = (contacts[f] & (contact_heel_bit(side) | contact_toe_bit(side))) != 0;
      if (point && !(contacts[f] & contact_planted_bit(side))) {
        return make_error(where + "frame " + std::to_string(f) + ": the " + (side == 0 ? "left" : "right") +
                          " foot's heel or toe is in contact but the foot is not planted");
      }
    }
  }
  return {};
}

std::string no_animation_explanation(std::string_view reason) {
  if (!reason.empty()) return std::string(reason);
  return "the file does not record why (it predates format 7): its clips' skeletons differ (the build warned, "
         "naming them: build one skeleton per database), it was built with --no-animation, or it is a format 1 file";
}

Error missing_animation_error(std::string_view what, std::string_view reason) {
  return make_error(std::string(what) + ": the database has no animation section: " +
                    no_animation_explanation(reason) + "; rebuild it with `mmvk build` from clips of one skeleton");
}

}  // namespace mmvk
