// The crowd's up-front bounds (host/crowd/setup/crowd_limits.hpp, issue 23, checked
// by validate() in crowd_settings.hpp, issue 30): the agents, the time
// options and tick count are refused outside their documented ranges with
// the option and the value as given named, and the memory estimate grows with what the run
// keeps (agents, seconds with --html) so the documented maximum is refused
// before any allocation instead of dying of bad_alloc.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "setup/crowd_limits.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::crowd {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

Status check_time_options(const CrowdSettings& settings) { return validate(settings, SettingNames::Flags); }

CrowdSettings with(double seconds, double rate, double interval) {
  CrowdSettings o;
  o.seconds = seconds;
  o.rate_hz = rate;
  o.search_interval_s = interval;
  return o;
}

// The random scenario's wait at each goal (--wait-at-goals), seconds.
CrowdSettings waiting(double seconds) {
  CrowdSettings o;
  o.wait_at_goals_s = seconds;
  return o;
}

TEST(CrowdLimits, TimeOptionsInRangeAreAccepted) {
  EXPECT_TRUE(check_time_options(CrowdSettings{}).ok());
  EXPECT_EQ(CrowdSettings{}.wait_at_goals_s, 0.0);  // the documented default: leave each goal at once
  EXPECT_TRUE(check_time_options(waiting(kMaxGoalWaitS)).ok());
  // mmvk.Crowd's keyword spelling.
  EXPECT_NE(validate(waiting(-1.0), SettingNames::Keywords).message().find("wait_at_goals -1: expected"),
            std::string::npos);
  EXPECT_TRUE(check_time_options(with(1.0, kMinRateHz, kMinSearchIntervalS)).ok());
  EXPECT_TRUE(check_time_options(with(1.0, kMaxRateHz, kMaxSearchIntervalS)).ok());
  EXPECT_TRUE(check_time_options(with(1.0 / 30.0, 30.0, 0.1)).ok());  // exactly one tick
  EXPECT_EQ(tick_count(with(10.0, 30.0, 0.1)), 300u);
}

TEST(CrowdLimits, TimeOptionsOutOfRangeNameTheOption) {
  const struct {
    CrowdSettings options;
    const char* expected;
  } cases[] = {
      {with(10.0, 1e-6, 0.1), "--rate 1e-06"},
      {with(10.0, 0.5, 0.1), "--rate 0.5"},
      {with(1.0, 5000.0, 0.1), "--rate 5000"},
      {with(10.0, 30.0, 1e-300), "--search-interval 1e-300"},
      {with(10.0, 30.0, 1e6), "--search-interval 1e+06"},
      {with(0.01, 30.0, 0.1), "0 ticks"},
      {with(1e-9, 1000.0, 0.1), "0 ticks"},
      {with(1e6, 30.0, 0.1), "over 10000000 ticks"},
      // The value as given, never its rounded print inside the bounds.
      {with(10.0, 0.9999999, 0.1), "--rate 0.9999999: expected 1 to 1000"},
      {with(10.0, 30.0, 3600.001), "--search-interval 3600.001: expected"},
      {with(333333.4, 30.0, 0.1), "--seconds 333333.4 at --rate 30: over 10000000 ticks"},
      {waiting(-0.5), "--wait-at-goals -0.5: expected 0 to 3600 seconds"},
      {waiting(3601.0), "--wait-at-goals 3601: expected 0 to 3600 seconds"},
      {waiting(std::nan("")), "--wait-at-goals nan: expected 0 to 3600 seconds"},
  };
  for (const auto& c : cases) {
    const Status status = check_time_options(c.options);
    ASSERT_FALSE(status.ok()) << c.expected;
    EXPECT_TRUE(contains(status.message(), c.expected)) << status.message();
  }
}

TEST(CrowdLimits, TheAgentCountIsTheSearchsBatchLimit) {
  CrowdSettings settings;
  settings.agents = kMaxAgents;
  EXPECT_TRUE(check_time_options(settings).ok());
  EXPECT_EQ(std::size_t{kMaxAgents}, kMaxBatch);
  settings.agents = std::uint64_t{kMaxAgents} + 1;
  const Status over = check_time_options(settings);
  ASSERT_FALSE(over.ok());
  EXPECT_TRUE(contains(over.message(), "--agents 1048577: expected 1 to 1048576")) << over.message();
  settings.agents = 0;
  EXPECT_FALSE(check_time_options(settings).ok());
  // mmvk.Crowd's keywords, and a negative count named as given.
  const Status negative = check_agent_count(-3.0, SettingNames::Keywords);
  ASSERT_FALSE(negative.ok());
  EXPECT_TRUE(contains(negative.message(), "agents -3: expected 1 to")) << negative.message();
}

TEST(CrowdLimits, TheMemoryEstimateGrowsWithWhatTheRunKeeps) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  const CrowdSettings plain = with(10.0, 30.0, 0.1);
  const RunOutputs none;
  RunOutputs page;
  page.html = true;
  // Linear in the agents above the process's fixed share.
  const std::uint64_t small = estimate_crowd_bytes(plain, none, db, 1000, 8000);
  const std::uint64_t twice = estimate_crowd_bytes(plain, none, db, 2000, 16000);
  const std::uint64_t large = estimate_crowd_bytes(plain, none, db, 100000, 800000);
  EXPECT_GT(large - small, 90 * (twice - small));
  // A page keeps every sample: it grows with the seconds, a run without one does not.
  const std::uint64_t with_page = estimate_crowd_bytes(plain, page, db, 1000, 8000);
  EXPECT_GT(with_page, small);
  CrowdSettings long_run = plain;
  long_run.seconds = 100.0;
  EXPECT_GT(estimate_crowd_bytes(long_run, page, db, 1000, 8000) - small, 5 * (with_page - small));
  // The documented maximum with a page of an hour: far beyond any machine.
  long_run.seconds = 3600.0;
  EXPECT_GT(estimate_crowd_bytes(long_run, page, db, kMaxAgents, 8ull * kMaxAgents), std::uint64_t{1} << 40);
  EXPECT_GT(memory_limit_bytes(), std::uint64_t{1} << 26);
}

TEST(CrowdLimits, ARunOverTheLimitIsRefusedWithBothFigures) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  CrowdSettings options = with(3600.0, 30.0, 0.1);
  options.agents = kMaxAgents;
  RunOutputs page;
  page.html = true;
  const Status status = check_crowd_memory(options, page, db, nullptr, SettingNames::Flags);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "1048576 agents for 3600 s with --html would need about")) << status.message();
  EXPECT_TRUE(contains(status.message(), "GiB this process may use")) << status.message();
  options.agents = 10;
  options.seconds = 1.0;
  EXPECT_TRUE(check_crowd_memory(options, page, db, nullptr, SettingNames::Flags).ok());
}

}  // namespace
}  // namespace mmvk::crowd
