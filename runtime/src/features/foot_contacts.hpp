// The foot contact detection of foot_contacts.hpp on a clip's global joint
// positions. The database build's animation step and the foot_contact
// channel both call it.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/import/motion.hpp"

namespace mmvk::detail {

struct ClipContacts {
  std::array<int, 2> toes{-1, -1};   // left, right toe joint; -1 where the skeleton has none
  std::array<int, 2> heels{-1, -1};  // left, right heel (ankle) joint; -1 where it does not resolve
  std::vector<std::uint8_t> bits;    // [frames], FootContact bits
  // Both feet have a contact point (a toe or a heel); else bits are all 0.
  bool resolved() const { return (toes[0] >= 0 || heels[0] >= 0) && (toes[1] >= 0 || heels[1] >= 0); }
};

// `positions` are the model-space joint positions [frames x joints] of a clip
// of `skeleton` at `fps`.
ClipContacts detect_foot_contacts(const Skeleton& skeleton, std::span<const glm::vec3> positions,
                                  std::uint32_t frames, float fps, const FootContactParams& params);

}  // namespace mmvk::detail
