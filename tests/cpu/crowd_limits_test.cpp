// The crowd's up-front bounds (host/crowd/crowd_limits.hpp, issue 23): the
// time options and tick count are refused outside their documented ranges
// with the option named, and the memory estimate grows with what the run
// keeps (agents, seconds with --html) so the documented maximum is refused
// before any allocation instead of dying of bad_alloc.
#include <gtest/gtest.h>

#include <string>

#include "crowd_limits.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::crowd {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

CrowdOptions with(double seconds, double rate, double interval) {
  CrowdOptions o;
  o.seconds = seconds;
  o.rate_hz = rate;
  o.search_interval_s = interval;
  return o;
}

TEST(CrowdLimits, TimeOptionsInRangeAreAccepted) {
  EXPECT_TRUE(check_time_options(CrowdOptions{}).ok());
  EXPECT_TRUE(check_time_options(with(1.0, kMinRateHz, kMinSearchIntervalS)).ok());
  EXPECT_TRUE(check_time_options(with(1.0, kMaxRateHz, kMaxSearchIntervalS)).ok());
  EXPECT_TRUE(check_time_options(with(1.0 / 30.0, 30.0, 0.1)).ok());  // exactly one tick
  EXPECT_EQ(tick_count(with(10.0, 30.0, 0.1)), 300u);
}

TEST(CrowdLimits, TimeOptionsOutOfRangeNameTheOption) {
  const struct {
    CrowdOptions options;
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
  };
  for (const auto& c : cases) {
    const Status status = check_time_options(c.options);
    ASSERT_FALSE(status.ok()) << c.expected;
    EXPECT_TRUE(contains(status.message(), c.expected)) << status.message();
  }
}

TEST(CrowdLimits, TheMemoryEstimateGrowsWithWhatTheRunKeeps) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  const CrowdOptions plain = with(10.0, 30.0, 0.1);
  CrowdOptions page = plain;
  page.html = "page.html";
  // Linear in the agents above the process's fixed share.
  const std::uint64_t small = estimate_crowd_bytes(plain, db, 1000, 8000);
  const std::uint64_t twice = estimate_crowd_bytes(plain, db, 2000, 16000);
  const std::uint64_t large = estimate_crowd_bytes(plain, db, 100000, 800000);
  EXPECT_GT(large - small, 90 * (twice - small));
  // A page keeps every sample: it grows with the seconds, a run without one does not.
  const std::uint64_t with_page = estimate_crowd_bytes(page, db, 1000, 8000);
  EXPECT_GT(with_page, small);
  CrowdOptions long_page = page;
  long_page.seconds = 100.0;
  EXPECT_GT(estimate_crowd_bytes(long_page, db, 1000, 8000) - small, 5 * (with_page - small));
  // The documented maximum with a page of an hour: far beyond any machine.
  long_page.seconds = 3600.0;
  EXPECT_GT(estimate_crowd_bytes(long_page, db, kMaxAgents, 8ull * kMaxAgents), std::uint64_t{1} << 44);
  EXPECT_GT(memory_limit_bytes(), std::uint64_t{1} << 26);
}

TEST(CrowdLimits, ARunOverTheLimitIsRefusedWithBothFigures) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  CrowdOptions options = with(3600.0, 30.0, 0.1);
  options.agents = kMaxAgents;
  options.html = "page.html";
  const Status status = check_crowd_memory(options, db, nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_TRUE(contains(status.message(), "10000000 agents for 3600 s with --html would need about")) << status.message();
  EXPECT_TRUE(contains(status.message(), "GiB this process may use")) << status.message();
  options.agents = 10;
  options.seconds = 1.0;
  EXPECT_TRUE(check_crowd_memory(options, db, nullptr).ok());
}

}  // namespace
}  // namespace mmvk::crowd
