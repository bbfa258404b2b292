// Critically damped springs: the closed forms behind inertialization (an
// offset decaying to zero) and trajectory prediction (a velocity tracking a
// goal), after Holden's "Spring-It-On" (2021). Header-only, no state.
//
// Half-life h: the time in which a spring released at rest covers about half
// of its distance to the goal; the decay rate is y = 2 ln 2 / h. For an offset
// released at rest the remaining fraction after t is (1 + y t) e^(-y t):
// 0.41 after one half-life, 0.0077 after five.
#pragma once

#include <cmath>

#include <glm/vec3.hpp>

namespace mmvk {

inline constexpr float kLn2 = 0.69314718056f;
inline constexpr float kPi = 3.14159265359f;

// Decay rate y of a half-life (seconds, > 0).
inline float spring_rate(float half_life) { return 2.0f * kLn2 / half_life; }

// Wraps an angle to [-pi, pi].
inline float wrap_angle(float a) {
  if (a >= -kPi && a <= kPi) return a;  // the usual case, without fmod
  a = std::fmod(a + kPi, 2.0f * kPi);
  if (a < 0.0f) a += 2.0f * kPi;
  return a - kPi;
}

// An offset x with velocity v decaying critically to 0 over dt seconds.
template <class T>
inline void spring_decay(T& x, T& v, float half_life, float dt) {
  const float y = spring_rate(half_life);
  const T j1 = v + x * y;
  const float e = std::exp(-y * dt);
  x = (x + j1 * dt) * e;
  v = (v - j1 * (y * dt)) * e;
}

// A position x whose velocity v (and acceleration a) tracks the goal velocity
// `goal` with a critically damped spring of `half_life`, advanced by dt.
inline void spring_velocity_step(glm::vec3& x, glm::vec3& v, glm::vec3& a, const glm::vec3& goal, float half_life,
                                 float dt) {
  const float y = spring_rate(half_life);
  const glm::vec3 j0 = v - goal;
  const glm::vec3 j1 = a + j0 * y;
  const float e = std::exp(-y * dt);
  x = e * (-j1 / (y * y) + (-j0 - j1 * dt) / y) + j1 / (y * y) + j0 / y + goal * dt + x;
  v = e * (j0 + j1 * dt) + goal;
  a = e * (a - j1 * y * dt);
}

// An angle (radians) and its rate tracking the goal angle along the shorter
// way, advanced by dt.
inline void spring_angle_step(float& angle, float& rate, float goal, float half_life, float dt) {
  float x = wrap_angle(angle - goal);
  spring_decay(x, rate, half_life, dt);
  angle = goal + x;
}

}  // namespace mmvk
