// The viewer's level of detail as the user chooses it (host/crowd/setup/
// detail_agents.hpp, issue 32): `--detail-agents` takes a count or a list of
// indices and ranges, every malformed spec is refused naming the option, the
// choice is checked against the crowd once its size is known, and the
// memory estimate counts the characters chosen.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "setup/crowd_limits.hpp"
#include "setup/detail_agents.hpp"
#include "support/search_test_data.hpp"

namespace mmvk::crowd {
namespace {

constexpr const char* kOption = "--detail-agents";

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::vector<std::uint32_t> resolved(const std::string& spec, std::uint64_t agents) {
  const Result<DetailAgents> choice = parse_detail_agents(spec, kOption);
  EXPECT_TRUE(choice.ok()) << spec << ": " << choice.message();
  if (!choice.ok()) return {};
  Result<std::vector<std::uint32_t>> chosen = resolve_detail_agents(*choice, agents, kOption);
  EXPECT_TRUE(chosen.ok()) << spec << ": " << chosen.message();
  return chosen.ok() ? *chosen : std::vector<std::uint32_t>{};
}

TEST(DetailAgents, CountsListsAndRanges) {
  EXPECT_EQ(resolved("3", 10), (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(resolved("0", 10), std::vector<std::uint32_t>{});  // none: a page without whole poses
  EXPECT_EQ(resolved("10", 10).size(), 10u);                   // the whole crowd
  EXPECT_EQ(resolved("0-2,7,4-5", 10), (std::vector<std::uint32_t>{0, 1, 2, 4, 5, 7}));
  EXPECT_EQ(resolved("9-9", 10), (std::vector<std::uint32_t>{9}));  // one character alone
  EXPECT_EQ(resolved(" 8 , 1-2 ", 10), (std::vector<std::uint32_t>{1, 2, 8}));
  EXPECT_EQ(resolved("0-9,42,100-104", 1000).size(), 16u);  // the help's example
}

TEST(DetailAgents, TheDefaultIsTheFirst32OrTheWholeSmallerCrowd) {
  const auto first = resolve_detail_agents(std::nullopt, 1000, kOption);
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->size(), std::size_t{kDefaultDetailAgents});
  EXPECT_EQ(first->back(), kDefaultDetailAgents - 1);
  const auto small = resolve_detail_agents(std::nullopt, 5, kOption);
  ASSERT_TRUE(small.ok());
  EXPECT_EQ(small->size(), 5u);
  EXPECT_EQ(detail_agent_count(std::nullopt, 1000), kDefaultDetailAgents);
  EXPECT_EQ(detail_agent_count(std::nullopt, 5), 5u);
}

TEST(DetailAgents, MalformedSpecsAreRefusedNamingTheOption) {
  const struct {
    const char* spec;
    const char* expected;
  } cases[] = {
      {"", "an empty list"},
      {"  ", "an empty list"},
      {"x", "expected a count N or a list"},
      {"3x", "expected a count N or a list"},
      {"-3", "'-3' is not an index or a range"},
      {"+3", "expected a count N or a list"},
      {"1.5", "expected a count N or a list"},
      {"0-", "'0-' is not an index or a range"},
      {"0-9,,12", "an empty item is not an index"},
      {"0-9,", "an empty item is not an index"},
      {",", "an empty item is not an index"},
      {"1-2-3", "'1-2-3' is not an index or a range"},
      {"9-3", "the range 9-3 runs backwards; write it 3-9"},
      {"4,4", "character 4 is listed twice"},
      {"0-9,5", "character 5 is listed twice"},
      {"0-4,3-8", "character 3 is listed twice"},
      {"99999999999999999999", "expected a count N or a list"},
  };
  for (const auto& c : cases) {
    const Result<DetailAgents> parsed = parse_detail_agents(c.spec, kOption);
    ASSERT_FALSE(parsed.ok()) << "'" << c.spec << "' was accepted";
    EXPECT_TRUE(contains(parsed.message(), std::string(kOption) + " '" + c.spec + "'")) << parsed.message();
    EXPECT_TRUE(contains(parsed.message(), c.expected)) << parsed.message();
  }
}

TEST(DetailAgents, ACountOrAnIndexBeyondTheCrowdIsRefused) {
  const Result<DetailAgents> count = parse_detail_agents("21", kOption);
  ASSERT_TRUE(count.ok());
  const auto over = resolve_detail_agents(*count, 20, kOption);
  ASSERT_FALSE(over.ok());
  EXPECT_TRUE(contains(over.message(), "--detail-agents 21: the crowd has 20 characters")) << over.message();
  const Result<DetailAgents> list = parse_detail_agents("0-4,20", kOption);
  ASSERT_TRUE(list.ok());
  const auto beyond = resolve_detail_agents(*list, 20, kOption);
  ASSERT_FALSE(beyond.ok());
  EXPECT_TRUE(contains(beyond.message(), "--detail-agents: character 20 is beyond the crowd (0 to 19)"))
      << beyond.message();
  EXPECT_TRUE(resolve_detail_agents(*list, 21, kOption).ok());
}

TEST(DetailAgents, AListOfIndicesInAnyOrder) {
  const std::vector<std::int64_t> indices = {7, 2, 3};
  const Result<DetailAgents> choice = detail_agents_from_list(indices, "detail_agents");
  ASSERT_TRUE(choice.ok()) << choice.message();
  const auto chosen = resolve_detail_agents(*choice, 8, "detail_agents");
  ASSERT_TRUE(chosen.ok());
  EXPECT_EQ(*chosen, (std::vector<std::uint32_t>{2, 3, 7}));
  EXPECT_EQ(detail_agent_count(*choice, 8), 3u);
  const std::vector<std::int64_t> twice = {1, 5, 1}, negative = {0, -1};
  const auto repeated = detail_agents_from_list(twice, "detail_agents");
  ASSERT_FALSE(repeated.ok());
  EXPECT_TRUE(contains(repeated.message(), "detail_agents: character 1 is listed twice")) << repeated.message();
  EXPECT_FALSE(detail_agents_from_list(negative, "detail_agents").ok());
  const auto empty = detail_agents_from_list({}, "detail_agents");
  ASSERT_FALSE(empty.ok());
  EXPECT_TRUE(contains(empty.message(), "detail_agents: an empty list")) << empty.message();
}

// The page's recording keeps each detailed character's whole pose every
// tick and each of its queries: the estimate grows with the set, by the
// same amount for the same number of characters wherever they are.
TEST(DetailAgents, TheMemoryEstimateGrowsWithTheSet) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  CrowdSettings settings;
  settings.seconds = 20.0;
  RunOutputs page;
  page.html = true;
  const auto estimate = [&](const char* spec) {
    CrowdSettings s = settings;
    if (spec) s.detail_agents = *parse_detail_agents(spec, kOption);
    return estimate_crowd_bytes(s, page, db, 1000, 8000);
  };
  const std::uint64_t none = estimate("0"), default_set = estimate(nullptr), first_32 = estimate("32");
  const std::uint64_t first_100 = estimate("100"), scattered_100 = estimate("0-49,500-549");
  EXPECT_EQ(default_set, first_32);
  EXPECT_LT(none, first_32);
  EXPECT_LT(first_32, first_100);
  EXPECT_EQ(first_100, scattered_100);
  // Linear in the characters chosen: 100 cost 100/32 of what 32 cost.
  EXPECT_NEAR(double(first_100 - none) / double(first_32 - none), 100.0 / 32.0, 1e-6);
  // Without a page nothing is kept in detail.
  CrowdSettings all = settings;
  all.detail_agents = *parse_detail_agents("1000", kOption);
  EXPECT_EQ(estimate_crowd_bytes(all, RunOutputs{}, db, 1000, 8000),
            estimate_crowd_bytes(settings, RunOutputs{}, db, 1000, 8000));
}

// The memory check refuses a set that would not fit, and its message names
// --detail-agents among what to lower.
TEST(DetailAgents, TheMemoryCheckCountsTheSetAndNamesIt) {
  const Database db = test::synthetic_database({.frames = 500, .clips = 2});
  CrowdSettings settings;
  settings.seconds = 3600.0;
  settings.agents = 100000;
  RunOutputs page;
  page.html = true;
  settings.detail_agents = *parse_detail_agents("0", kOption);
  const std::uint64_t without = estimate_crowd_bytes(settings, page, db, 100000, 800000);
  settings.detail_agents = *parse_detail_agents("100000", kOption);
  const std::uint64_t with = estimate_crowd_bytes(settings, page, db, 100000, 800000);
  ASSERT_GT(with, without);
  const Status status = check_crowd_memory(settings, page, db, nullptr, SettingNames::Flags);
  ASSERT_FALSE(status.ok()) << "the estimate " << with << " fits this machine";
  EXPECT_TRUE(contains(status.message(), "--detail-agents")) << status.message();
}

}  // namespace
}  // namespace mmvk::crowd
