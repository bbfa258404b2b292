// Analytic two-bone IK (foot_ik.hpp): the solved knee is built from the law
// of cosines in the plane of the hip-to-target axis and the animated pole,
// then the two rotations are the shortest arcs onto the solved bones. No
// inverse trigonometry: acos of a clamped dot product is where the usual
// formulations lose precision (and their derivative blows up) near a
// straight leg.
#include "mmvk/animation/foot_ik.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace mmvk {

namespace {

// Lengths below this (metres) count as zero: far below any bone, far above
// float noise on joint positions of a character a few metres from the origin.
constexpr float kTiny = 1e-7f;
// The pole is blended with the hint below this fraction of the leg's length.
constexpr float kStraightPole = 0.01f;
// The ankle counts as on its target within this distance (metres): the
// tolerance of a held foot.
constexpr float kReached = 1e-3f;

const glm::vec3 kDown(0.0f, -1.0f, 0.0f);

// Any unit vector perpendicular to the unit vector v.
glm::vec3 perpendicular(const glm::vec3& v) {
  const glm::vec3 other = std::abs(v.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
  return glm::normalize(glm::cross(v, other));
}

}  // namespace

float soft_reach(float distance, float start, float limit) {
  const float width = limit - start;
  if (!(width > kTiny)) return std::min(distance, limit);
  if (distance <= start) return distance;
  return start + width * (1.0f - std::exp(-(distance - start) / width));
}

glm::quat rotation_between(const glm::vec3& from, const glm::vec3& to) {
  const float from2 = glm::dot(from, from);
  const float to2 = glm::dot(to, to);
  if (!(from2 > kTiny * kTiny) || !(to2 > kTiny * kTiny)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  // The half-way quaternion (|a||b| + a.b, a x b), normalized: exact for
  // small angles, where an angle-axis construction divides by the sine, and
  // two square roots in all (the solver's hottest call).
  const float lengths = std::sqrt(from2 * to2);
  const float w = lengths + glm::dot(from, to);
  if (w < 1e-6f * lengths) {  // opposite: a half turn about any perpendicular axis
    const glm::vec3 axis = perpendicular(from / std::sqrt(from2));
    return glm::quat(0.0f, axis.x, axis.y, axis.z);
  }
  const glm::vec3 v = glm::cross(from, to);
  const float scale = 1.0f / std::sqrt(w * w + glm::dot(v, v));
  return glm::quat(w * scale, v.x * scale, v.y * scale, v.z * scale);
}

namespace {

// The animated leg's lengths and directions, and where the ankle is put.
struct Leg {
  glm::vec3 hip_knee, knee_ankle, hip_ankle;
  float upper, lower, leg, extension;
  glm::vec3 along;  // unit, hip toward where the ankle goes
  float distance;   // |target - hip| (the animated extension for an infinite target)
};

Leg measure(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle, const glm::vec3& target) {
  Leg l;
  l.hip_knee = knee - hip;
  l.knee_ankle = ankle - knee;
  l.hip_ankle = ankle - hip;
  l.upper = glm::length(l.hip_knee);
  l.lower = glm::length(l.knee_ankle);
  l.leg = l.upper + l.lower;
  l.extension = glm::length(l.hip_ankle);
  glm::vec3 to_target = target - hip;
  l.distance = glm::length(to_target);
  if (!std::isfinite(l.distance)) {  // an infinite target: keep the animated ankle
    to_target = l.hip_ankle;
    l.distance = l.extension;
  }
  // The direction the ankle is put along: to the target, or for a target at
  // the hip the animated leg's direction (then the upper bone's, then down).
  l.along = kDown;
  if (l.distance > kTiny) {
    l.along = to_target / l.distance;
  } else if (l.extension > kTiny) {
    l.along = l.hip_ankle / l.extension;
  } else if (l.upper > kTiny) {
    l.along = l.hip_knee / l.upper;
  }
  return l;
}

// The unit bend direction from `pole`, perpendicular to the ankle's line;
// `fallback` where the pole lies along it, then any perpendicular.
glm::vec3 bend_direction(const Leg& l, const glm::vec3& pole, const glm::vec3& fallback) {
  glm::vec3 bend = pole - l.along * glm::dot(pole, l.along);
  float bend_length = glm::length(bend);
  if (!(bend_length > kTiny) || !std::isfinite(bend_length)) {
    bend = fallback - l.along * glm::dot(fallback, l.along);
    bend_length = glm::length(bend);
  }
  return bend_length > kTiny && std::isfinite(bend_length) ? bend / bend_length : perpendicular(l.along);
}

// The law of cosines for a bend direction already chosen.
TwoBoneIkSolution solve_in_plane(const Leg& l, const glm::vec3& hip, const glm::vec3& bend, float soft_start) {
  // Reach: the animated extension is always reachable; beyond the soft start
  // the leg approaches full extension asymptotically.
  const float start = std::min(l.leg, std::max(soft_start * l.leg, l.extension));
  const float reach = std::max(soft_reach(l.distance, start, l.leg), std::abs(l.upper - l.lower));

  // Law of cosines for the angle at the hip between the thigh and the
  // hip-ankle line.
  float cos_hip = 1.0f;
  const float denominator = 2.0f * l.upper * reach;
  if (denominator > kTiny) {
    cos_hip = std::clamp((l.upper * l.upper + reach * reach - l.lower * l.lower) / denominator, -1.0f, 1.0f);
  }
  const float sin_hip = std::sqrt(std::max(0.0f, 1.0f - cos_hip * cos_hip));

  TwoBoneIkSolution solution;
  solution.knee = hip + l.upper * (cos_hip * l.along + sin_hip * bend);
  solution.ankle = hip + reach * l.along;
  solution.upper = rotation_between(l.hip_knee, solution.knee - hip);
  solution.lower = rotation_between(solution.upper * l.knee_ankle, solution.ankle - solution.knee);
  solution.clamped = std::abs(reach - l.distance) > kReached;
  return solution;
}

// The animated knee's offset from the hip-ankle line.
glm::vec3 animated_pole(const Leg& l) {
  const glm::vec3 axis = l.extension > kTiny ? l.hip_ankle / l.extension : l.along;
  return l.hip_knee - axis * glm::dot(l.hip_knee, axis);
}

}  // namespace

TwoBoneIkSolution solve_two_bone_ik(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                                    const glm::vec3& target, const glm::vec3& pole_hint, float soft_start) {
  const Leg l = measure(hip, knee, ankle, target);
  glm::vec3 hint = pole_hint;
  const float hint_length = glm::length(hint);
  hint = hint_length > kTiny && std::isfinite(hint_length) ? hint / hint_length : glm::vec3(0.0f, 0.0f, 1.0f);

  // The pole: the animated knee's offset from the hip-ankle line, with the
  // hint blended in linearly as it vanishes (continuous in the pose).
  glm::vec3 pole = animated_pole(l);
  const float pole_length = glm::length(pole);
  const float straight = kStraightPole * l.leg;
  if (pole_length < straight) pole += (straight - pole_length) * hint;
  return solve_in_plane(l, hip, bend_direction(l, pole, hint), soft_start);
}

TwoBoneIkSolution solve_two_bone_ik_toward(const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                                           const glm::vec3& target, const glm::vec3& pole, float soft_start) {
  const Leg l = measure(hip, knee, ankle, target);
  return solve_in_plane(l, hip, bend_direction(l, pole, animated_pole(l)), soft_start);
}

}  // namespace mmvk
