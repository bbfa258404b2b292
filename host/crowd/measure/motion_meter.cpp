#include "measure/motion_meter.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "mmvk/import/character.hpp"

namespace mmvk::crowd {

namespace {

constexpr double kRadToDeg = 57.29577951308232;
// Bins: knee speed 1 deg/s up to 20,000; heights 0.5 mm up to 1 m;
// accelerations 0.05 m/s^2 up to 2,000.
constexpr double kKneeBin = 1.0;
constexpr std::size_t kKneeBins = 20000;
constexpr double kHeightBin = 0.05;
constexpr std::size_t kHeightBins = 2000;
constexpr double kAccelerationBin = 0.05;
constexpr std::size_t kAccelerationBins = 40000;
// Longer spacings would only come from tick rates far above any database's.
constexpr std::uint32_t kMaxAccelerationStep = 16;

int bone(const Skeleton& skeleton, const char* role) {
  Result<int> found = find_bone(skeleton, role);
  return found ? *found : -1;
}

double horizontal(const glm::vec3& a, const glm::vec3& b) {
  const double dx = double(a.x) - b.x, dz = double(a.z) - b.z;
  return std::sqrt(dx * dx + dz * dz);
}

// The angle between the thigh and the shin (0: a straight leg), radians;
// NaN for a zero-length segment.
float knee_angle(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle) {
  const glm::vec3 thigh = knee - hip, shin = ankle - knee;
  const float lengths = glm::length(thigh) * glm::length(shin);
  if (!(lengths > 1e-12f)) return std::numeric_limits<float>::quiet_NaN();
  // atan2 of |cross| and dot stays accurate near a straight leg, where acos does not.
  return std::atan2(glm::length(glm::cross(thigh, shin)), glm::dot(thigh, shin));
}

}  // namespace

bool LegJoints::has_knees() const {
  for (int side = 0; side < 2; ++side) {
    if (upper[side] < 0 || lower[side] < 0 || ankle[side] < 0) return false;
  }
  return true;
}

LegJoints find_leg_joints(const AnimationData& animation) {
  const Skeleton& skeleton = animation.skeleton;
  LegJoints legs;
  legs.upper = {bone(skeleton, "@left_upper_leg"), bone(skeleton, "@right_upper_leg")};
  legs.lower = {bone(skeleton, "@left_lower_leg"), bone(skeleton, "@right_lower_leg")};
  legs.ankle = {bone(skeleton, "@left_foot"), bone(skeleton, "@right_foot")};
  legs.contact = animation.contact_joints;
  return legs;
}

MotionMeter::MotionMeter(std::size_t streams, std::size_t joints, const MotionMeterParams& params)
    : streams_(streams),
      joints_(joints),
      params_(params),
      ring_(2 * std::size_t(std::clamp<std::uint32_t>(params.acceleration_step, 1, kMaxAccelerationStep)) + 1),
      jump_ticks_(std::max<std::uint64_t>(ring_ - 1, std::uint64_t(std::ceil(params.jump_window_s / params.dt - 1e-9)))),
      seen_(streams, 0),
      since_jump_(streams, std::numeric_limits<std::uint64_t>::max()),
      last_points_(4 * streams),
      last_points_animated_(4 * streams),
      last_contacts_(streams, 0),
      last_knee_(2 * streams, 0.0f),
      poses_(ring_ * streams * joints),
      knee_speed_(kKneeBin, kKneeBins),
      height_(kHeightBin, kHeightBins),
      acceleration_(kAccelerationBin, kAccelerationBins),
      acceleration_at_jumps_(kAccelerationBin, kAccelerationBins) {
  params_.acceleration_step = std::uint32_t(ring_ / 2);
}

void MotionMeter::record(const Tick& tick) {
  have_animated_ = have_animated_ || !tick.animated.empty();
  have_locks_ = have_locks_ || !tick.locked.empty();
  have_clamps_ = have_clamps_ || !tick.clamped.empty();
  for (std::size_t s = 0; s < streams_; ++s) {
    const auto pose = tick.shown.subspan(s * joints_, joints_);
    if (!tick.jumped.empty() && tick.jumped[s]) since_jump_[s] = 0;
    if (params_.legs.has_feet()) record_feet(s, tick);
    if (params_.legs.has_knees()) record_knees(s, pose);
    record_acceleration(s, pose, since_jump_[s] < jump_ticks_);
    ++seen_[s];
    if (since_jump_[s] != std::numeric_limits<std::uint64_t>::max()) ++since_jump_[s];
  }
  ++ticks_;
}

void MotionMeter::record_feet(std::size_t s, const Tick& tick) {
  const LegJoints& legs = params_.legs;
  const std::uint8_t contacts = tick.contacts[s];
  for (int f = 0; f < 2; ++f) {
    const std::size_t foot = 2 * s + std::size_t(f);
    // The foot's two points: its contact joint (the toe) and its ankle.
    const int joints[2] = {legs.contact[f], legs.ankle[f] >= 0 ? legs.ankle[f] : legs.contact[f]};
    glm::vec3 shown[2], animated[2];
    for (int k = 0; k < 2; ++k) {
      shown[k] = tick.shown[s * joints_ + std::size_t(joints[k])];
      animated[k] = tick.animated.empty() ? shown[k] : tick.animated[s * joints_ + std::size_t(joints[k])];
    }
    const std::uint8_t planted = f == 0 ? kContactLeft : kContactRight;
    const std::uint8_t heel = f == 0 ? kContactLeftHeel : kContactRightHeel;
    const std::uint8_t toe = f == 0 ? kContactLeftToe : kContactRightToe;
    ++foot_ticks_;
    if (!tick.clamped.empty() && tick.clamped[foot]) ++clamped_ticks_;
    if (contacts & planted) {
      ++contact_ticks_;
      if (!tick.locked.empty() && tick.locked[foot]) ++locked_ticks_;
      const double height_cm = 100.0 * (double(shown[0].y) - params_.planted_height[std::size_t(f)]);
      height_sum_cm_ += height_cm;
      height_.add(std::abs(height_cm));
      if (seen_[s] > 0 && (last_contacts_[s] & planted)) {
        // The point on the ground: the heel while only the heel touches.
        const int k = (contacts & heel) && !(contacts & toe) ? 1 : 0;
        sliding_sum_ += horizontal(shown[k], last_points_[2 * foot + std::size_t(k)]) / params_.dt;
        sliding_animated_sum_ += horizontal(animated[k], last_points_animated_[2 * foot + std::size_t(k)]) / params_.dt;
        ++sliding_samples_;
      }
    }
    for (int k = 0; k < 2; ++k) {
      last_points_[2 * foot + std::size_t(k)] = shown[k];
      last_points_animated_[2 * foot + std::size_t(k)] = animated[k];
    }
  }
  last_contacts_[s] = contacts;
}

void MotionMeter::record_knees(std::size_t s, std::span<const glm::vec3> pose) {
  const LegJoints& legs = params_.legs;
  for (int f = 0; f < 2; ++f) {
    const float angle = knee_angle(pose[std::size_t(legs.upper[f])], pose[std::size_t(legs.lower[f])],
                                   pose[std::size_t(legs.ankle[f])]);
    float& last = last_knee_[2 * s + std::size_t(f)];
    if (seen_[s] > 0 && std::isfinite(angle) && std::isfinite(last)) {
      knee_speed_.add(std::abs(double(angle) - last) * kRadToDeg / params_.dt);
    }
    last = angle;
  }
}

void MotionMeter::record_acceleration(std::size_t s, std::span<const glm::vec3> pose, bool near_jump) {
  const std::size_t k = params_.acceleration_step;
  const auto slot = [&](std::uint64_t ticks_ago) {
    return poses_.data() + (((ticks_ + ring_ - ticks_ago % ring_) % ring_) * streams_ + s) * joints_;
  };
  glm::vec3* now = slot(0);
  std::copy(pose.begin(), pose.end(), now);
  if (seen_[s] < 2 * k || joints_ == 0) return;
  const glm::vec3* before = slot(k);
  const glm::vec3* first = slot(2 * k);
  double sum = 0.0;
  for (std::size_t j = 0; j < joints_; ++j) sum += glm::length(now[j] - 2.0f * before[j] + first[j]);
  const double step = double(k) * params_.dt;
  const double acceleration = sum / double(joints_) / (step * step);
  (near_jump ? acceleration_at_jumps_ : acceleration_).add(acceleration);
}

MotionFigures MotionMeter::figures() const {
  MotionFigures out;
  if (sliding_samples_) {
    out.foot_sliding_cm_s = 100.0 * sliding_sum_ / double(sliding_samples_);
    if (have_animated_) out.foot_sliding_before_ik_cm_s = 100.0 * sliding_animated_sum_ / double(sliding_samples_);
  }
  if (have_locks_ && contact_ticks_) out.foot_lock_fraction = double(locked_ticks_) / double(contact_ticks_);
  if (have_clamps_ && foot_ticks_) out.ik_reach_clamped_fraction = double(clamped_ticks_) / double(foot_ticks_);
  out.knee_speed_p99_deg_s = knee_speed_.quantile(0.99);
  if (height_.count()) {
    out.foot_height_in_contact_cm_mean = height_sum_cm_ / double(height_.count());
    out.foot_height_in_contact_cm_p95 = height_.quantile(0.95);
  }
  out.pose_acceleration_p99_m_s2 = acceleration_.quantile(0.99);
  out.pose_acceleration_p99_at_jumps_m_s2 = acceleration_at_jumps_.quantile(0.99);
  return out;
}

}  // namespace mmvk::crowd
