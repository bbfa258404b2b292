// The gait from the command (gait_choice.hpp): bands with hysteresis, the
// phases of a start and a stop, and the tag constraint of each.
#include <gtest/gtest.h>

#include "mmvk/animation/gait_choice.hpp"

namespace mmvk {
namespace {

constexpr float kDt = 1.0f / 30.0f;

GaitTagBits bits() {
  GaitTagBits b;
  for (std::size_t i = 0; i < b.bit.size(); ++i) {
    b.bit[i] = TagMask{1} << (i + 3);  // after three manifest tags
    b.all |= b.bit[i];
  }
  return b;
}

TagMask bit(GaitBand band) { return bits().bit[std::size_t(band)]; }
TagMask stop() { return bits().bit[kGaitStopTag]; }

GaitOptions everything() {
  GaitOptions o;
  o.band.fill(true);
  o.idle = true;
  return o;
}

TEST(GaitChoice, ACommandWaveringAboutAThresholdKeepsItsBand) {
  const GaitBandParams p;  // jog from 2 m/s, hysteresis 10%
  GaitState s = first_gait_state(p, 1.9f);
  EXPECT_EQ(s.band, GaitBand::Walk);
  EXPECT_EQ(s.phase, GaitPhase::Move);
  for (const float speed : {2.05f, 1.95f, 2.15f, 1.85f}) {
    s = next_gait_state(p, s, speed, speed, kDt);
    EXPECT_EQ(s.band, GaitBand::Walk) << speed;
  }
  s = next_gait_state(p, s, 2.2f, 2.2f, kDt);
  EXPECT_EQ(s.band, GaitBand::Jog);
  s = next_gait_state(p, s, 1.85f, 1.85f, kDt);
  EXPECT_EQ(s.band, GaitBand::Jog) << "down only under 2 x 0.9";
  s = next_gait_state(p, s, 1.75f, 1.75f, kDt);
  EXPECT_EQ(s.band, GaitBand::Walk);
  s = next_gait_state(p, s, 3.5f, 3.5f, kDt);
  EXPECT_EQ(s.band, GaitBand::Run) << "a jump in the command crosses two bands at once";
}

TEST(GaitChoice, AStopThenAStandThenAStartThenMoving) {
  const GaitBandParams p;
  GaitState s = first_gait_state(p, 1.3f);
  s = next_gait_state(p, s, 0.0f, 1.0f, kDt);
  EXPECT_EQ(s.band, GaitBand::Stand);
  EXPECT_EQ(s.phase, GaitPhase::Stop) << "told to stand while the root still moves";
  s = next_gait_state(p, s, 0.0f, 0.1f, kDt);
  EXPECT_EQ(s.phase, GaitPhase::Stand);
  s = next_gait_state(p, s, 1.3f, 0.0f, kDt);
  EXPECT_EQ(s.phase, GaitPhase::Start);
  EXPECT_EQ(s.phase_seconds, 0.0f);
  s = next_gait_state(p, s, 1.3f, 0.5f, kDt);
  EXPECT_EQ(s.phase, GaitPhase::Start);
  s = next_gait_state(p, s, 1.3f, 1.2f, kDt);
  EXPECT_EQ(s.phase, GaitPhase::Move) << "90% of the command reached";
  // A start that lasts ends after transition_seconds at the latest.
  s = next_gait_state(p, next_gait_state(p, s, 0.0f, 0.0f, kDt), 1.3f, 0.0f, kDt);
  ASSERT_EQ(s.phase, GaitPhase::Start);
  for (int t = 0; t < int(p.transition_seconds / kDt) + 1; ++t) s = next_gait_state(p, s, 1.3f, 0.3f, kDt);
  EXPECT_EQ(s.phase, GaitPhase::Move);
}

TEST(GaitChoice, EachPhaseConstrainsItsSearches) {
  const GaitTagBits b = bits();
  const GaitOptions all = everything();
  GaitState stand{GaitBand::Stand, GaitPhase::Stand, 0.0f};
  EXPECT_EQ(gait_constraint(stand, all, b), (GaitConstraint{bit(GaitBand::Stand), 0, false}));
  GaitOptions no_idle = all;
  no_idle.idle = false;
  EXPECT_EQ(gait_constraint(stand, no_idle, b), (GaitConstraint{0, 0, true})) << "rests on a held frame";
  EXPECT_EQ(gait_constraint({GaitBand::Stand, GaitPhase::Stop, 0.0f}, all, b), GaitConstraint{});
  EXPECT_EQ(gait_constraint({GaitBand::Walk, GaitPhase::Start, 0.0f}, all, b),
            (GaitConstraint{0, bit(GaitBand::Stand) | stop(), false}));
  EXPECT_EQ(gait_constraint({GaitBand::Walk, GaitPhase::Move, 0.0f}, all, b).exclude_any,
            bit(GaitBand::Stand) | stop() | bit(GaitBand::Run));
  EXPECT_EQ(gait_constraint({GaitBand::Jog, GaitPhase::Move, 0.0f}, all, b).exclude_any,
            bit(GaitBand::Stand) | stop());
  EXPECT_EQ(gait_constraint({GaitBand::Run, GaitPhase::Move, 0.0f}, all, b).exclude_any,
            bit(GaitBand::Stand) | stop() | bit(GaitBand::Walk));
}

TEST(GaitChoice, ABandTheTagsLeaveNoFrameOfFallsBackToAnyMovingFrame) {
  const GaitTagBits b = bits();
  GaitOptions walk_only;
  walk_only.band = {true, true, false, false};
  EXPECT_EQ(gait_constraint({GaitBand::Run, GaitPhase::Move, 0.0f}, walk_only, b).exclude_any,
            bit(GaitBand::Stand) | stop())
      << "no jog or run: the walk plays, never a stand";
  EXPECT_EQ(gait_constraint({GaitBand::Walk, GaitPhase::Move, 0.0f}, walk_only, b).exclude_any,
            bit(GaitBand::Stand) | stop() | bit(GaitBand::Run));
}

}  // namespace
}  // namespace mmvk
