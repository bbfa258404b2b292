// The two-bone IK solver (foot_ik.hpp) on random and degenerate legs: the
// rotations it returns, applied to the animated chain, put the ankle on
// reachable targets, keep the bone lengths and the knee's plane, and stay
// finite for unreachable and degenerate input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/geometric.hpp>

#include "mmvk/animation/foot_ik.hpp"

namespace mmvk {
namespace {

const glm::vec3 kForward(0.0f, 0.0f, 1.0f);

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::quat& q) { return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z); }

// The chain after applying a solution's rotations (what the foot locker does
// to the joints' global rotations).
struct Chain {
  glm::vec3 knee;
  glm::vec3 ankle;
};
Chain apply(const TwoBoneIkSolution& s, const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle) {
  const glm::vec3 k = hip + s.upper * (knee - hip);
  return {k, k + s.lower * (s.upper * (ankle - knee))};
}

glm::vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<float> normal;
  for (;;) {
    const glm::vec3 v(normal(rng), normal(rng), normal(rng));
    if (glm::length(v) > 1e-3f) return glm::normalize(v);
  }
}

// A bent leg: hip at a random point, thigh and shin of random lengths with a
// knee angle of 20 to 150 degrees.
struct Leg {
  glm::vec3 hip, knee, ankle;
  float upper, lower;
};
Leg random_leg(std::mt19937& rng) {
  std::uniform_real_distribution<float> length(0.2f, 0.6f);
  std::uniform_real_distribution<float> bend(0.35f, 2.6f);
  std::uniform_real_distribution<float> place(-3.0f, 3.0f);
  Leg leg;
  leg.upper = length(rng);
  leg.lower = length(rng);
  leg.hip = glm::vec3(place(rng), 1.0f + place(rng), place(rng));
  const glm::vec3 thigh = random_unit(rng);
  glm::vec3 side = glm::normalize(glm::cross(thigh, random_unit(rng)));
  leg.knee = leg.hip + leg.upper * thigh;
  const glm::vec3 shin = glm::angleAxis(bend(rng), side) * thigh;
  leg.ankle = leg.knee + leg.lower * shin;
  return leg;
}

TEST(SoftReach, IdentityBelowStartContinuousAndBelowTheLimit) {
  EXPECT_EQ(soft_reach(0.5f, 0.8f, 1.0f), 0.5f);
  EXPECT_EQ(soft_reach(0.8f, 0.8f, 1.0f), 0.8f);
  float previous = soft_reach(0.8f, 0.8f, 1.0f);
  for (float d = 0.801f; d < 5.0f; d += 0.001f) {
    const float r = soft_reach(d, 0.8f, 1.0f);
    EXPECT_LE(r, 1.0f) << d;  // in float it reaches the limit far out
    EXPECT_TRUE(d >= 1.2f || r < 0.999f) << d;
    EXPECT_GE(r, previous) << d;          // increasing
    EXPECT_LE(r - previous, 0.0011f) << d;  // slope at most 1: no jump
    previous = r;
  }
  EXPECT_GT(soft_reach(1.0f, 0.8f, 1.0f), 0.92f);  // 0.8 + 0.2 (1 - 1/e)
  EXPECT_EQ(soft_reach(1.5f, 1.0f, 1.0f), 1.0f);   // no soft zone: a hard clamp
  EXPECT_EQ(soft_reach(0.5f, 1.0f, 1.0f), 0.5f);
}

TEST(RotationBetween, TurnsOneDirectionOntoAnother) {
  std::mt19937 rng(11);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 a = random_unit(rng) * 0.7f;
    const glm::vec3 b = random_unit(rng) * 2.0f;
    EXPECT_LT(glm::length(rotation_between(a, b) * glm::normalize(a) - glm::normalize(b)), 1e-5f) << i;
  }
  const glm::vec3 x(1.0f, 0.0f, 0.0f);
  EXPECT_LT(glm::length(rotation_between(x, -x) * x + x), 1e-6f);  // opposite: a half turn
  const glm::quat zero = rotation_between(glm::vec3(0.0f), x);
  EXPECT_EQ(zero, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
}

TEST(TwoBoneIk, ReachesReachableTargetsWithinAMillimetre) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  float worst = 0.0f;
  for (int i = 0; i < 2000; ++i) {
    const Leg leg = random_leg(rng);
    const float min = std::abs(leg.upper - leg.lower) + 0.01f;
    const float max = 0.94f * (leg.upper + leg.lower);  // below the soft start (0.95)
    const glm::vec3 target = leg.hip + random_unit(rng) * (min + (max - min) * unit(rng));
    const TwoBoneIkSolution s = solve_two_bone_ik(leg.hip, leg.knee, leg.ankle, target, kForward, 0.95f);
    const Chain chain = apply(s, leg.hip, leg.knee, leg.ankle);
    const float error = glm::length(chain.ankle - target);
    worst = std::max(worst, error);
    ASSERT_LT(error, 1e-3f) << "leg " << i;
    EXPECT_LT(glm::length(s.ankle - target), 1e-4f) << i;
    EXPECT_FALSE(s.clamped) << i;
    // Rigid bones: the lengths are kept, and the rotations land where the
    // solution says.
    EXPECT_NEAR(glm::length(chain.knee - leg.hip), leg.upper, 1e-5f) << i;
    EXPECT_NEAR(glm::length(chain.ankle - chain.knee), leg.lower, 1e-5f) << i;
    EXPECT_LT(glm::length(chain.knee - s.knee), 1e-4f) << i;
  }
  std::printf("worst ankle error over 2000 random legs: %.3g m\n", double(worst));
}

TEST(TwoBoneIk, TargetAtTheAnimatedAnkleKeepsThePose) {
  std::mt19937 rng(6);
  for (int i = 0; i < 500; ++i) {
    const Leg leg = random_leg(rng);
    const TwoBoneIkSolution s = solve_two_bone_ik(leg.hip, leg.knee, leg.ankle, leg.ankle, kForward, 0.95f);
    EXPECT_LT(glm::length(s.knee - leg.knee), 1e-5f) << i;
    EXPECT_LT(glm::length(s.ankle - leg.ankle), 1e-5f) << i;
    EXPECT_FALSE(s.clamped) << i;
  }
}

TEST(TwoBoneIk, KneeStaysInTheAnimatedKneesPlane) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coefficient(-0.5f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    const Leg leg = random_leg(rng);
    const glm::vec3 normal = glm::normalize(glm::cross(leg.knee - leg.hip, leg.ankle - leg.hip));
    // A target in the plane of hip, knee and ankle, within reach.
    glm::vec3 offset = coefficient(rng) * (leg.knee - leg.hip) + coefficient(rng) * (leg.ankle - leg.hip);
    const float reach = 0.9f * (leg.upper + leg.lower);
    if (glm::length(offset) > reach) offset *= reach / glm::length(offset);
    const glm::vec3 target = leg.hip + offset;
    const TwoBoneIkSolution s = solve_two_bone_ik(leg.hip, leg.knee, leg.ankle, target, kForward, 0.95f);
    const Chain chain = apply(s, leg.hip, leg.knee, leg.ankle);
    EXPECT_LT(std::abs(glm::dot(chain.knee - leg.hip, normal)), 1e-5f) << i;
    EXPECT_LT(std::abs(glm::dot(chain.ankle - leg.hip, normal)), 1e-5f) << i;
    // And bent the animated way: the solved knee's offset from the
    // hip-target line points along the animated pole (the knee's offset
    // from the animated hip-ankle line).
    const glm::vec3 animated_axis = glm::normalize(leg.ankle - leg.hip);
    const glm::vec3 pole = leg.knee - leg.hip - animated_axis * glm::dot(leg.knee - leg.hip, animated_axis);
    const glm::vec3 axis = glm::normalize(target - leg.hip);
    const glm::vec3 animated = pole - axis * glm::dot(pole, axis);
    const glm::vec3 solved = chain.knee - leg.hip - axis * glm::dot(chain.knee - leg.hip, axis);
    if (glm::length(animated) > 0.02f && glm::length(solved) > 1e-3f) {  // not straight
      EXPECT_GT(glm::dot(animated, solved), 0.0f) << i;
    }
  }
}

TEST(TwoBoneIk, UnreachableTargetsAreSoftClampedNotSnapped) {
  const glm::vec3 hip(0.0f, 1.0f, 0.0f);
  const glm::vec3 knee(0.0f, 0.58f, 0.15f);
  const glm::vec3 ankle(0.0f, 0.16f, 0.0f);
  const float leg = glm::length(knee - hip) + glm::length(ankle - knee);
  // The target moves away from the hip past full extension: the solved
  // ankle moves continuously, never reaches full extension, and the knee
  // angle changes by a bounded amount per step (no pop).
  glm::vec3 previous_knee = apply(solve_two_bone_ik(hip, knee, ankle, hip + glm::vec3(0.0f, -0.7f, 0.0f), kForward, 0.95f),
                                 hip, knee, ankle).knee;
  for (float d = 0.7f; d < 1.5f; d += 0.002f) {
    const glm::vec3 target = hip + glm::vec3(0.0f, -d, 0.0f);
    const TwoBoneIkSolution s = solve_two_bone_ik(hip, knee, ankle, target, kForward, 0.95f);
    const Chain chain = apply(s, hip, knee, ankle);
    EXPECT_LE(glm::length(chain.ankle - hip), leg + 1e-6f) << d;
    EXPECT_TRUE(d >= leg + 0.05f || glm::length(chain.ankle - hip) < leg - 1e-3f) << d;  // still bent
    EXPECT_LT(glm::length(chain.knee - previous_knee), 0.01f) << d;
    if (d < 0.95f * leg) {
      EXPECT_FALSE(s.clamped) << d;
    } else if (d > 0.95f * leg + 0.01f) {
      EXPECT_TRUE(s.clamped) << d;
    }
    previous_knee = chain.knee;
  }
}

TEST(TwoBoneIk, NoNanForDegenerateLegsAndTargets) {
  const glm::vec3 hip(0.1f, 0.9f, 0.0f);
  struct Case {
    const char* name;
    glm::vec3 knee, ankle, target;
  };
  const Case cases[] = {
      {"zero-length upper", hip, hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.1f, -0.3f, 0.1f)},
      {"zero-length lower", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.0f, -0.4f, 0.0f),
       hip + glm::vec3(0.1f, -0.3f, 0.1f)},
      {"both zero", hip, hip, hip + glm::vec3(0.1f, -0.3f, 0.1f)},
      {"straight leg, target nearer", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       hip + glm::vec3(0.0f, -0.5f, 0.1f)},
      {"straight leg, target along it", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       hip + glm::vec3(0.0f, -0.6f, 0.0f)},
      {"straight leg, target beyond", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       hip + glm::vec3(0.0f, -2.0f, 0.0f)},
      {"folded leg", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip, hip + glm::vec3(0.0f, -0.5f, 0.0f)},
      {"target at the hip", hip + glm::vec3(0.0f, -0.4f, 0.05f), hip + glm::vec3(0.0f, -0.8f, 0.0f), hip},
      {"target at the hip, straight", hip + glm::vec3(0.0f, -0.4f, 0.0f), hip + glm::vec3(0.0f, -0.8f, 0.0f), hip},
      {"target along the pole", hip + glm::vec3(0.0f, -0.3f, 0.3f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       hip + glm::vec3(0.0f, -0.3f, 0.3f)},
      {"target far away", hip + glm::vec3(0.0f, -0.4f, 0.05f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       glm::vec3(1e6f, -1e6f, 3e5f)},
      {"target at infinity", hip + glm::vec3(0.0f, -0.4f, 0.05f), hip + glm::vec3(0.0f, -0.8f, 0.0f),
       glm::vec3(INFINITY, 0.0f, 0.0f)},
  };
  for (const Case& c : cases) {
    for (const glm::vec3& hint : {kForward, glm::vec3(0.0f), glm::vec3(0.0f, -1.0f, 0.0f)}) {
      const TwoBoneIkSolution s = solve_two_bone_ik(hip, c.knee, c.ankle, c.target, hint, 0.95f);
      ASSERT_TRUE(finite(s.upper) && finite(s.lower) && finite(s.knee) && finite(s.ankle)) << c.name;
      EXPECT_NEAR(glm::length(s.upper), 1.0f, 1e-5f) << c.name;
      EXPECT_NEAR(glm::length(s.lower), 1.0f, 1e-5f) << c.name;
      const Chain chain = apply(s, hip, c.knee, c.ankle);
      ASSERT_TRUE(finite(chain.knee) && finite(chain.ankle)) << c.name;
      // The bones keep their lengths whatever the target.
      EXPECT_NEAR(glm::length(chain.knee - hip), glm::length(c.knee - hip), 1e-5f) << c.name;
      EXPECT_NEAR(glm::length(chain.ankle - chain.knee), glm::length(c.ankle - c.knee), 1e-5f) << c.name;
    }
  }
  // A straight leg asked to bend folds toward the hint (the character's
  // forward) when the animation gives no knee direction.
  const TwoBoneIkSolution bent = solve_two_bone_ik(hip, hip + glm::vec3(0.0f, -0.4f, 0.0f),
                                                   hip + glm::vec3(0.0f, -0.8f, 0.0f),
                                                   hip + glm::vec3(0.0f, -0.6f, 0.0f), kForward, 0.95f);
  EXPECT_GT(bent.knee.z, 0.1f);
  EXPECT_LT(glm::length(bent.ankle - (hip + glm::vec3(0.0f, -0.6f, 0.0f))), 1e-5f);
}

}  // namespace
}  // namespace mmvk
