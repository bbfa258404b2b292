#include "features/foot_contacts.hpp"

#include <algorithm>
#include <string>

#include <glm/geometric.hpp>

#include "mmvk/character.hpp"

namespace mmvk::detail {

namespace {

// The contact bone of one side: the configured bone, else the ankle with a
// raised height threshold.
struct ContactBone {
  int joint = -1;
  float max_height = 0.0f;
};

ContactBone resolve_contact_bone(const Skeleton& skeleton, const std::string& bone, const char* ankle,
                                 const FootContactParams& params) {
  if (Result<int> joint = find_bone(skeleton, bone); joint.ok()) return {*joint, params.max_height};
  if (Result<int> joint = find_bone(skeleton, ankle); joint.ok()) {
    return {*joint, params.max_height + (params.height_above_clip_floor ? 0.0f : params.ankle_height_extra)};
  }
  return {};
}

// The floor_percentile of a bone's height over the clip.
float floor_height(std::span<const glm::vec3> positions, std::size_t joints, std::size_t joint, float percentile) {
  std::vector<float> heights;
  heights.reserve(positions.size() / joints);
  for (std::size_t i = joint; i < positions.size(); i += joints) heights.push_back(positions[i].y);
  const std::size_t k = static_cast<std::size_t>(std::clamp(percentile, 0.0f, 1.0f) * float(heights.size() - 1));
  std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(k), heights.end());
  return heights[k];
}

}  // namespace

ClipContacts detect_foot_contacts(const Skeleton& skeleton, std::span<const glm::vec3> positions,
                                  std::uint32_t frames, float fps, const FootContactParams& params) {
  ClipContacts out;
  out.bits.assign(frames, 0);
  const std::size_t joints = skeleton.size();
  // Contacts from the model-space bone trajectory: low and slow.
  const ContactBone sides[2] = {resolve_contact_bone(skeleton, params.left_bone, "@left_foot", params),
                                resolve_contact_bone(skeleton, params.right_bone, "@right_foot", params)};
  if (frames == 0 || sides[0].joint < 0 || sides[1].joint < 0) return out;
  for (int s = 0; s < 2; ++s) {
    const std::size_t j = static_cast<std::size_t>(sides[s].joint);
    out.joints[static_cast<std::size_t>(s)] = sides[s].joint;
    const float floor = params.height_above_clip_floor ? floor_height(positions, joints, j, params.floor_percentile) : 0.0f;
    for (std::uint32_t f = 0; f < frames; ++f) {
      const std::uint32_t a = f > 0 ? f - 1 : f;
      const std::uint32_t b = f + 1 < frames ? f + 1 : f;
      const float speed =
          b > a ? glm::length(positions[b * joints + j] - positions[a * joints + j]) * fps / float(b - a) : 0.0f;
      const float height = positions[f * joints + j].y;
      if (height < floor + sides[s].max_height && speed < params.max_speed) {
        out.bits[f] |= s == 0 ? kContactLeft : kContactRight;
      }
    }
  }
  return out;
}

}  // namespace mmvk::detail
