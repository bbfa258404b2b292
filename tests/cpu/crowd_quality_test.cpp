// The crowd's quality figures on motions whose answers are known.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "quality_meter.hpp"

namespace mmvk::crowd {
namespace {

TEST(CrowdQuality, TrajectoryErrorComparesWithWhatWasDesiredOneSecondEarlier) {
  // 10 Hz ticks, 2 agents. Each tick the desired position 1 s ahead is where
  // the agent will really be, plus 0.25 m for agent 0 and 0.75 m for agent 1
  // along z: the median of {0.25, 0.75, ...} over many ticks lies in
  // [0.25, 0.75], and with three agents the middle one is the median.
  const double dt = 0.1;
  QualityMeter meter(3, 2, dt);
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

TEST(CrowdQuality, FootSlidingCountsOnlyTicksInContactAtBothEnds) {
  const double dt = 1.0 / 30.0;
  QualityMeter meter(1, 2, dt);
  // Left foot in contact, sliding 0.3 m/s along x; right foot swinging fast
  // (not in contact) and must not count.
  for (int t = 0; t < 30; ++t) {
    const std::vector<float> feet{float(0.3 * t * dt), 0.0f, float(4.0 * t * dt), 1.0f};
    const std::vector<std::uint8_t> contact{1, 0};
    meter.record_feet(feet, contact);
    meter.end_tick();
  }
  EXPECT_NEAR(meter.foot_sliding_cm_s(), 30.0, 1e-3);
  meter.add_transitions(3);
  EXPECT_NEAR(meter.transitions_per_agent_s(), 3.0, 1e-9);  // 3 jumps, 1 agent, 1 s
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
