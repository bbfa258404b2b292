// The foot contact detection of foot_contacts.hpp on a clip's global joint
// positions. The database build's animation step and the foot_contact
// channel both call it.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/foot_contacts.hpp"
#include "mmvk/motion.hpp"

namespace mmvk::detail {

struct ClipContacts {
  std::array<int, 2> joints{-1, -1};  // left, right contact bone; -1 when a side did not resolve
  std::vector<std::uint8_t> bits;     // [frames], FootContact bits; all 0 when a side did not resolve
};

// `positions` are the model-space joint positions [frames x joints] of a clip
// of `skeleton` at `fps`.
ClipContacts detect_foot_contacts(const Skeleton& skeleton, std::span<const glm::vec3> positions,
                                  std::uint32_t frames, float fps, const FootContactParams& params);

}  // namespace mmvk::detail
