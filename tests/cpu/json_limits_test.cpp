// The JSON checks every input gets (mmvk/common/json_check.hpp), against hostile
// documents (issue 34): deep nesting is refused before anything walks it,
// the check is linear in the number of objects, syntax errors give the
// byte offset and the reason, and keys are echoed safely.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/input_text.hpp"
#include "mmvk/common/json_check.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/query/pose_query.hpp"

namespace mmvk {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string nested(std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

// A manifest whose inline schema nests 100,000 arrays crashed `mmvk build`
// (the schema is dumped recursively); every parser now stops at the depth.
TEST(JsonLimits, DeepNestingIsRefusedOnEveryParser) {
  EXPECT_TRUE(check_json_text(nested(kMaxJsonDepth), "ok.json").ok());
  const Status deep = check_json_text(nested(kMaxJsonDepth + 1), "deep.json");
  ASSERT_FALSE(deep.ok());
  EXPECT_TRUE(contains(deep.message(), "deep.json: arrays and objects nested more than 256 levels deep"))
      << deep.message();
  const std::string very_deep = nested(100000);
  const Result<Manifest> manifest =
      parse_manifest_json(R"({"clips": [{"file": "a.bvh"}], "schema": )" + very_deep + "}", "m.json", ".");
  ASSERT_FALSE(manifest.ok());
  EXPECT_TRUE(contains(manifest.message(), "m.json: arrays and objects nested")) << manifest.message();
  const Result<FeatureSchema> schema = parse_schema_json(R"({"channels": )" + very_deep + "}", "s.json");
  ASSERT_FALSE(schema.ok());
  EXPECT_TRUE(contains(schema.message(), "s.json: arrays and objects nested")) << schema.message();
  EXPECT_FALSE(parse_pose_targets_json(R"({"targets": )" + very_deep + "}", "t.json").ok());
  EXPECT_FALSE(check_json_text(R"({"a":)" + std::string(50000, '[') + "{", "o.json").ok());
}

// The check was quadratic in the number of objects in an array (nlohmann's
// callback parser scans the array at every object's end): 200,000 agents
// (8 MB) took 9 s, 46 MB did not finish. Linear, 200,000 objects take well
// under a second (bench/json_check_bench.cpp measures 8, 16 and 46 MB).
// Seconds to check a scenario of `objects` agents (the best of `tries`).
double seconds_to_check(int objects, int tries) {
  std::string text = "{\"agents\": [";
  for (int i = 0; i < objects; ++i) text += i == 0 ? "{\"start\": [1, 2], \"speed\": \"walk\"}" : ",{\"start\": [1, 2], \"speed\": \"walk\"}";
  text += "]}";
  double best = INFINITY;
  for (int t = 0; t < tries; ++t) {
    const auto start = std::chrono::steady_clock::now();
    const Status status = check_json_text(text, "big.json");
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    EXPECT_TRUE(status.ok()) << status.message();
  }
  return best;
}

// The check was quadratic in the number of objects (200,000 took 67 s).
// Eight times the objects must take about eight times as long, not 64: a
// ratio within one run, so the machine's speed, its load and the
// sanitizers cancel out (bench/json_check_bench.cpp has the times).
TEST(JsonLimits, AnArrayOfManyObjectsIsCheckedInLinearTime) {
  const double small = seconds_to_check(20000, 3);
  const double large = seconds_to_check(160000, 2);
  EXPECT_LT(large, 32.0 * small) << "20,000 objects " << small << " s, 160,000 objects " << large << " s";
}

TEST(JsonLimits, SyntaxErrorsGiveTheByteOffsetAndTheReason) {
  const Status brace = check_json_text(R"({"a": 1,})", "m.json");
  ASSERT_FALSE(brace.ok());
  EXPECT_TRUE(contains(brace.message(), "m.json: not valid JSON at byte 8: syntax error while parsing object key"))
      << brace.message();
  const Status tail = check_json_text("{} x", "m.json");
  ASSERT_FALSE(tail.ok());
  EXPECT_TRUE(contains(tail.message(), "not valid JSON at byte 3: ")) << tail.message();
  EXPECT_TRUE(contains(tail.message(), "expected end of input")) << tail.message();
  // Valid syntax, out of range: it was "not valid JSON" like the rest.
  const Status huge = check_json_text(R"({"fps": 1e400})", "m.json");
  ASSERT_FALSE(huge.ok());
  EXPECT_TRUE(contains(huge.message(), "number overflow parsing '1e400'")) << huge.message();
  const Status empty = check_json_text("", "m.json");
  ASSERT_FALSE(empty.ok());
  EXPECT_TRUE(contains(empty.message(), "not valid JSON at byte 0: ")) << empty.message();
}

// A manifest key "\u001b]0;pwned\u0007\u001b[2J" was echoed with its escape
// bytes (it retitled and cleared the terminal), a 1 MB key made a 1 MB line.
TEST(JsonLimits, EchoedKeysAreEscapedAndBounded) {
  const std::string evil = R"(\u001b]0;pwned\u0007\u001b[2J)";
  const Status dup = check_json_text("{\"" + evil + "\": 1, \"" + evil + "\": 2}", "m.json");
  ASSERT_FALSE(dup.ok());
  EXPECT_TRUE(contains(dup.message(), R"(duplicate key "\x1b]0;pwned\x07\x1b[2J")")) << dup.message();
  const Result<Manifest> unknown = parse_manifest_json("{\"" + evil + "\": 1, \"clips\": []}", "m.json", ".");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.message().find('\x1b'), std::string::npos) << unknown.message();
  EXPECT_TRUE(contains(unknown.message(), R"(\x1b]0;pwned)")) << unknown.message();
  const std::string long_key(1 << 20, 'k');
  const Result<Manifest> big = parse_manifest_json("{\"" + long_key + "\": 1, \"clips\": []}", "m.json", ".");
  ASSERT_FALSE(big.ok());
  EXPECT_LT(big.message().size(), 200u) << big.message().size();
  const Result<FeatureSchema> schema = parse_schema_json("{\"" + evil + "\": []}", "s.json");
  ASSERT_FALSE(schema.ok());
  EXPECT_EQ(schema.message().find('\x1b'), std::string::npos) << schema.message();
}

// The OS reads a path only up to a NUL: a clip "131_01.bvh\u0000.junk" built
// 131_01.bvh with exit 0.
TEST(JsonLimits, ManifestPathsWithANulAreRefused) {
  for (const std::string& text : {std::string(R"({"clips": [{"file": "131_01.bvh\u0000.junk"}]})"),
                                  std::string(R"({"clips": ["131_01.bvh\u0000.junk"]})"),
                                  std::string(R"({"clips": ["a.bvh"], "schema": "s.json\u0000x"})")}) {
    const Result<Manifest> manifest = parse_manifest_json(text, "m.json", ".");
    ASSERT_FALSE(manifest.ok()) << text;
    EXPECT_TRUE(contains(manifest.message(), "the path holds a NUL byte at offset")) << manifest.message();
  }
}

TEST(JsonLimits, PrintableTextEscapesControlBytesAndCuts) {
  EXPECT_EQ(printable_text("walk_01"), "walk_01");
  EXPECT_EQ(printable_text("a\x1b[2J\x7f\n"), "a\\x1b[2J\\x7f\\x0a");
  EXPECT_EQ(printable_text("caf\xc3\xa9"), "caf\\xc3\\xa9");
  EXPECT_EQ(printable_text(std::string(100, 'x'), 4), "xxxx...");
  EXPECT_EQ(quoted_text("k"), "\"k\"");
  EXPECT_EQ(printable_text(std::string(1000, 'x')).size(), kMaxShownInputBytes + 3);
}

}  // namespace
}  // namespace mmvk
