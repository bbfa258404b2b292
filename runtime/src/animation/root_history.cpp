// The recorded root path of each character (root_history.hpp).
#include "mmvk/animation/root_history.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "mmvk/animation/spring.hpp"

namespace mmvk {

namespace {

// Yaw from a to b by the fraction t along the shorter arc.
float lerp_yaw(float a, float b, float t) { return wrap_angle(a + wrap_angle(b - a) * t); }

}  // namespace

RootHistory::RootHistory(std::uint32_t characters, float longest_past)
    : capacity_(static_cast<std::uint32_t>(std::ceil(std::max(longest_past, 0.0f) / kSpacing)) + 2),
      positions_(std::size_t{characters} * capacity_),
      yaws_(std::size_t{characters} * capacity_),
      head_(characters, 0),
      since_(characters, 0.0f),
      now_position_(characters),
      now_yaw_(characters, 0.0f) {}

void RootHistory::reset(std::uint32_t b, const glm::vec3& position, float yaw) {
  const std::size_t base = std::size_t{b} * capacity_;
  std::fill_n(positions_.begin() + static_cast<std::ptrdiff_t>(base), capacity_, position);
  std::fill_n(yaws_.begin() + static_cast<std::ptrdiff_t>(base), capacity_, yaw);
  head_[b] = 0;
  since_[b] = 0.0f;
  now_position_[b] = position;
  now_yaw_[b] = yaw;
}

void RootHistory::record(std::uint32_t b, float dt, const glm::vec3& position, float yaw) {
  assert(dt > 0.0f);
  const std::size_t base = std::size_t{b} * capacity_;
  // Samples fall at the newest sample's time plus whole spacings; those up
  // to now are interpolated between the previous root and this one. Only
  // the newest `capacity_` of them can matter, so a long step costs no more.
  const double elapsed = double(since_[b]) + double(dt);
  const double passed = std::floor(elapsed / double(kSpacing));
  const double first = std::max(1.0, passed - double(capacity_) + 1.0);
  for (double k = first; k <= passed; k += 1.0) {
    const auto t = static_cast<float>((k * double(kSpacing) - double(since_[b])) / double(dt));
    head_[b] = (head_[b] + 1) % capacity_;
    positions_[base + head_[b]] = now_position_[b] + (position - now_position_[b]) * t;
    yaws_[base + head_[b]] = lerp_yaw(now_yaw_[b], yaw, t);
  }
  since_[b] = static_cast<float>(elapsed - passed * double(kSpacing));
  now_position_[b] = position;
  now_yaw_[b] = yaw;
}

void RootHistory::at(std::uint32_t b, float seconds_ago, glm::vec3& position, float& yaw) const {
  const std::size_t base = std::size_t{b} * capacity_;
  const auto sample = [&](std::uint32_t age) { return base + (head_[b] + capacity_ - age) % capacity_; };
  const float since = since_[b];
  if (seconds_ago <= since) {
    // Between the newest sample and now.
    const float t = since > 0.0f ? seconds_ago / since : 0.0f;
    position = now_position_[b] + (positions_[sample(0)] - now_position_[b]) * t;
    yaw = lerp_yaw(now_yaw_[b], yaws_[sample(0)], t);
    return;
  }
  const float u = (seconds_ago - since) / kSpacing;
  if (u >= float(capacity_ - 1)) {
    position = positions_[sample(capacity_ - 1)];
    yaw = yaws_[sample(capacity_ - 1)];
    return;
  }
  const auto age = static_cast<std::uint32_t>(u);
  const float t = u - float(age);
  const std::size_t newer = sample(age);
  const std::size_t older = sample(age + 1);
  position = positions_[newer] + (positions_[older] - positions_[newer]) * t;
  yaw = lerp_yaw(yaws_[newer], yaws_[older], t);
}

}  // namespace mmvk
