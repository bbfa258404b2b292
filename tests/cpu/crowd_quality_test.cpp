// The crowd's quality figures on motions whose answers are known.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "measure/histogram.hpp"
#include "measure/motion_meter.hpp"
#include "measure/quality_meter.hpp"

namespace mmvk::crowd {
namespace {

TEST(CrowdQuality, TrajectoryErrorComparesWithWhatWasDesiredOneSecondEarlier) {
  // 10 Hz ticks, 2 agents. Each tick the desired position 1 s ahead is where
  // the agent will really be, plus 0.25 m for agent 0 and 0.75 m for agent 1
  // along z: the median of {0.25, 0.75, ...} over many ticks lies in
  // [0.25, 0.75], and with three agents the middle one is the median.
  const double dt = 0.1;
  QualityMeter meter(3, dt);
  const float speed = 1.5f;
  const float miss[3] = {0.25f, 0.5f, 0.75f};
  for (int t = 0; t < 50; ++t) {
    std::vector<float> desired(6), root(6);
    for (int a = 0; a < 3; ++a) {
      const float now = speed * float(t * dt);
      root[2 * a] = now, root[2 * a + 1] = float(a);
      desired[2 * a] = now + speed * 1.0f, desired[2 * a + 1] = float(a) + miss[a];
    }
    meter.record_trajectory(desired, root);
    meter.end_tick();
  }
  EXPECT_EQ(meter.trajectory_samples(), 3u * 40u);
  EXPECT_NEAR(meter.trajectory_error_m_median(), 0.5, 0.001);
}

TEST(CrowdQuality, TransitionsPerAgentSecond) {
  QualityMeter meter(1, 1.0 / 30.0);
  for (int t = 0; t < 30; ++t) meter.end_tick();
  meter.add_transitions(3);
  EXPECT_NEAR(meter.transitions_per_agent_s(), 3.0, 1e-9);  // 3 jumps, 1 agent, 1 s
}

TEST(CrowdQuality, HistogramQuantilesAndMean) {
  Histogram h(0.5, 10);  // [0, 5), the last bin open-ended
  for (int i = 1; i <= 100; ++i) h.add(0.04 * i - 0.01);  // 0.03 .. 3.99, none on a bin's edge
  EXPECT_EQ(h.count(), 100u);
  EXPECT_NEAR(h.mean(), 2.01, 1e-9);
  EXPECT_NEAR(h.quantile(0.5), 1.75, 1e-9);   // the 50th value, 1.99, lies in [1.5, 2)
  EXPECT_NEAR(h.quantile(0.99), 3.75, 1e-9);  // the 99th, 3.95, in [3.5, 4)
  h.add(1e9);
  h.add(-1.0);
  EXPECT_NEAR(h.quantile(1.0), 4.75, 1e-9);   // the open-ended last bin
  EXPECT_NEAR(h.quantile(0.0), 0.25, 1e-9);
  EXPECT_TRUE(std::isnan(Histogram(1.0, 4).quantile(0.5)));
}

// A stick figure of 9 joints: hips, then per side upper leg, knee, ankle, toe.
constexpr std::size_t kJoints = 9;
MotionMeterParams stick_params(double dt) {
  MotionMeterParams params;
  params.legs.upper = {1, 5};
  params.legs.lower = {2, 6};
  params.legs.ankle = {3, 7};
  params.legs.contact = {4, 8};
  params.dt = dt;
  params.planted_height = {0.04f, 0.04f};
  return params;
}

// Both legs straight down from hips at (x, 1, z); the toes 4 cm up.
std::vector<glm::vec3> standing(float x, float z) {
  std::vector<glm::vec3> pose(kJoints);
  pose[0] = {x, 1.0f, z};
  for (int side = 0; side < 2; ++side) {
    const float sx = x + (side == 0 ? 0.1f : -0.1f);
    pose[std::size_t(1 + 4 * side)] = {sx, 0.95f, z};
    pose[std::size_t(2 + 4 * side)] = {sx, 0.5f, z};
    pose[std::size_t(3 + 4 * side)] = {sx, 0.1f, z};
    pose[std::size_t(4 + 4 * side)] = {sx, 0.04f, z + 0.12f};
  }
  return pose;
}

TEST(MotionMeter, FeetSlidingLocksClampsAndHeightInContact) {
  const double dt = 1.0 / 30.0;
  MotionMeter meter(1, kJoints, stick_params(dt));
  // The left foot is flagged in contact and slides 0.3 m/s as shown, 0.5 m/s
  // before IK, 1 cm above its planted height; it is locked on the first 15
  // ticks; the right foot swings at 4 m/s (not in contact, so it must not
  // count) and is clamped on 3 ticks.
  for (int t = 0; t < 30; ++t) {
    std::vector<glm::vec3> shown = standing(0.0f, 0.0f), animated = standing(0.0f, 0.0f);
    shown[4] = {float(0.3 * t * dt), 0.05f, 0.0f};
    animated[4] = {float(0.5 * t * dt), 0.05f, 0.0f};
    shown[8] = animated[8] = {float(4.0 * t * dt), 0.3f, 0.0f};
    const std::uint8_t contacts[1] = {kContactLeft};
    const std::uint8_t locked[2] = {std::uint8_t(t < 15), 0};
    const std::uint8_t clamped[2] = {0, std::uint8_t(t < 3)};
    meter.record({shown, animated, contacts, locked, clamped, {}});
  }
  const MotionFigures f = meter.figures();
  EXPECT_NEAR(f.foot_sliding_cm_s, 30.0, 1e-3);
  EXPECT_NEAR(f.foot_sliding_before_ik_cm_s, 50.0, 1e-3);
  EXPECT_NEAR(f.foot_lock_fraction, 0.5, 1e-12);
  EXPECT_NEAR(f.ik_reach_clamped_fraction, 3.0 / 60.0, 1e-12);
  EXPECT_NEAR(f.foot_height_in_contact_cm_mean, 1.0, 1e-4);
  EXPECT_NEAR(f.foot_height_in_contact_cm_p95, 1.0, 0.05);
}

TEST(MotionMeter, SlidingFollowsThePointOnTheGround) {
  // A heel strike: the left ankle holds still while the foot rolls onto its
  // toe (the toe comes down and forward at 0.6 m/s). While the frame says
  // only the heel touches, the heel is what must not slide; once the toe
  // touches, the toe.
  const double dt = 1.0 / 30.0;
  MotionMeter meter(1, kJoints, stick_params(dt));
  for (int t = 0; t < 20; ++t) {
    std::vector<glm::vec3> pose = standing(0.0f, 0.0f);
    const bool rolling = t < 10;
    pose[4] = pose[3] + glm::vec3(0.0f, -0.06f, 0.12f + float(0.6 * std::min(t, 10) * dt));
    const std::uint8_t contacts[1] = {std::uint8_t(kContactLeft | (rolling ? kContactLeftHeel : kContactLeftToe))};
    meter.record({pose, {}, contacts, {}, {}, {}});
  }
  // 19 samples: 9 rolling on the heel (0), the one where the toe lands
  // (still moving, 60 cm/s), 9 on the toe (0).
  EXPECT_NEAR(meter.figures().foot_sliding_cm_s, 60.0 / 19.0, 1e-3);
}

TEST(MotionMeter, WithoutLocksOrAnimatedPoseThoseFiguresAreNotMeasured) {
  MotionMeter meter(1, kJoints, stick_params(1.0 / 30.0));
  const std::uint8_t contacts[1] = {kContactLeft | kContactRight};
  for (int t = 0; t < 5; ++t) meter.record({standing(0.0f, 0.0f), {}, contacts, {}, {}, {}});
  const MotionFigures f = meter.figures();
  EXPECT_NEAR(f.foot_sliding_cm_s, 0.0, 1e-9);
  EXPECT_TRUE(std::isnan(f.foot_sliding_before_ik_cm_s));
  EXPECT_TRUE(std::isnan(f.foot_lock_fraction));
  EXPECT_TRUE(std::isnan(f.ik_reach_clamped_fraction));
}

TEST(MotionMeter, KneeSpeedIsTheFlexionAngleRate) {
  // The left shin turns forward at 90 deg/s about the knee (the right leg
  // stays straight, 0 deg/s): half the knee-ticks at 90, so p99 is 90.
  const double dt = 1.0 / 60.0;
  MotionMeter meter(1, kJoints, stick_params(dt));
  const std::uint8_t contacts[1] = {0};
  for (int t = 0; t < 60; ++t) {
    std::vector<glm::vec3> pose = standing(0.0f, 0.0f);
    const double angle = 0.5 * 3.14159265358979 * t * dt;
    pose[3] = pose[2] + glm::vec3(0.0f, -0.4f * float(std::cos(angle)), 0.4f * float(std::sin(angle)));
    meter.record({pose, {}, contacts, {}, {}, {}});
  }
  EXPECT_NEAR(meter.figures().knee_speed_p99_deg_s, 90.0, 0.6);
}

TEST(MotionMeter, PoseAccelerationKeepsJumpsApartAndSpansTheFrameInterval) {
  // Every joint accelerates at 2 m/s^2 along x, sampled from a 30 fps
  // "clip" and played at 60 Hz with linear interpolation between frames:
  // with a spacing of 2 ticks (one frame) the acceleration is the clip's.
  const double fps = 30.0, dt = 1.0 / 60.0;
  MotionMeterParams params = stick_params(dt);
  params.acceleration_step = 2;
  params.jump_window_s = 0.0;  // only the samples whose poses span the jump
  MotionMeter meter(1, kJoints, params);
  const std::uint8_t contacts[1] = {0};
  auto x_at_frame = [](double f) { return 0.5 * 2.0 * (f / 30.0) * (f / 30.0); };
  for (int t = 0; t < 120; ++t) {
    const double f = t * dt * fps, f0 = std::floor(f);
    const double x = x_at_frame(f0) + (f - f0) * (x_at_frame(f0 + 1.0) - x_at_frame(f0));
    // A jump at tick 60: the pose steps 5 cm sideways.
    const std::uint8_t jumped[1] = {std::uint8_t(t == 60)};
    meter.record({standing(float(x), t >= 60 ? 0.05f : 0.0f), {}, contacts, {}, {}, jumped});
  }
  const MotionFigures f = meter.figures();
  EXPECT_NEAR(f.pose_acceleration_p99_m_s2, 2.0, 0.05);
  // 0.05 m over two frame intervals: 0.05 / (1/30)^2 = 45 m/s^2.
  EXPECT_NEAR(f.pose_acceleration_p99_at_jumps_m_s2, 45.0, 2.1);
}

TEST(MotionMeter, RestartedStreamsDoNotMeasureAcrossTheBreak) {
  // Two clips back to back: the second starts 10 m away. Nothing across the
  // break counts: no sliding, knee or acceleration sample spans it.
  MotionMeter meter(1, kJoints, stick_params(1.0 / 30.0));
  const std::uint8_t contacts[1] = {kContactLeft | kContactRight};
  for (int t = 0; t < 10; ++t) {
    if (t == 5) meter.restart(0);
    meter.record({standing(t < 5 ? 0.0f : 10.0f, 0.0f), {}, contacts, {}, {}, {}});
  }
  const MotionFigures f = meter.figures();
  EXPECT_NEAR(f.foot_sliding_cm_s, 0.0, 1e-9);
  EXPECT_NEAR(f.pose_acceleration_p99_m_s2, 0.025, 1e-9);  // all samples 0: the first bin's centre
  EXPECT_NEAR(f.knee_speed_p99_deg_s, 0.5, 1e-9);
}

TEST(CrowdQuality, PercentileIsTheNearestRank) {
  std::vector<double> samples;
  for (int i = 100; i >= 1; --i) samples.push_back(i);
  EXPECT_EQ(percentile(samples, 0.5), 50.0);
  EXPECT_EQ(percentile(samples, 0.99), 99.0);
  EXPECT_EQ(percentile(samples, 1.0), 100.0);
  EXPECT_TRUE(std::isnan(percentile({}, 0.5)));
}

}  // namespace
}  // namespace mmvk::crowd
