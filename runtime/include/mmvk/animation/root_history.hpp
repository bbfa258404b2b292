// The recorded path of each character's root: where it actually walked, for
// the past offsets of its queries' trajectory channels (as a pose recorder
// does), whatever the tick rate. Samples are kept at a fixed spacing
// (kSpacing seconds), interpolated from the ticks that straddle them, in a
// ring per character sized once for the longest past offset. World space:
// positions in metres (y = 0), yaws in radians.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace mmvk {

class RootHistory {
 public:
  static constexpr float kSpacing = 1.0f / 60.0f;  // seconds between samples

  RootHistory() = default;
  // `characters` rings long enough to answer at(b, -longest_past) (seconds, >= 0).
  RootHistory(std::uint32_t characters, float longest_past);

  // Forgets character b's path: it has always stood at (position, yaw).
  void reset(std::uint32_t b, const glm::vec3& position, float yaw);
  // Character b moved to (position, yaw) over the last dt seconds (> 0).
  // Allocates nothing; the work is bounded by the ring's size.
  void record(std::uint32_t b, float dt, const glm::vec3& position, float yaw);
  // Where character b was `seconds_ago` (>= 0) seconds ago: interpolated
  // between samples, the oldest sample beyond the ring.
  void at(std::uint32_t b, float seconds_ago, glm::vec3& position, float& yaw) const;

 private:
  std::uint32_t capacity_ = 0;       // samples per character
  std::vector<glm::vec3> positions_;  // [B x capacity] ring, newest at head_
  std::vector<float> yaws_;           // [B x capacity] (unwrapped along the ring)
  std::vector<std::uint32_t> head_;   // [B]
  std::vector<float> since_;          // [B] seconds from the newest sample to now
  std::vector<glm::vec3> now_position_;  // [B] the latest recorded root
  std::vector<float> now_yaw_;           // [B] (unwrapped, continuous with the ring)
};

}  // namespace mmvk
