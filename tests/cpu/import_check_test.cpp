// The build's check of an import (mmvk/import/import_check.hpp) on the shipped CMU
// subject 16 walk: right units and axis pass, a centimetre or metre reading
// of its CMU ASF units and a Z-up reading of the Y-up file are refused with
// the cause and the manifest field that fixes them, and accept_implausible
// builds them anyway. The shipped sets still build with the check on.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/import/import_check.hpp"
#include "mmvk/database/manifest.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

namespace fs = std::filesystem;

fs::path shipped(const std::string& relative) { return test::test_source_dir() / "../host/crowd/data" / relative; }

Result<Database> build_walk(const std::string& import) {
  const std::string text = R"({"fps": 30, "import": )" + import + R"(, "clips": [{"file": ")" +
                           shipped("cmu16/16_23.bvh").string() + R"(", "tags": ["walk"]}]})";
  Result<Manifest> manifest = parse_manifest_json(text, "walk.json", ".");
  EXPECT_TRUE(manifest.ok()) << manifest.message();
  return build_database(*manifest);
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ImportCheck, MeasuresAWalk) {
  const Result<BvhFile> bvh = load_bvh(shipped("cmu16/16_23.bvh"));
  ASSERT_TRUE(bvh.ok()) << bvh.message();
  const Result<Motion> motion = motion_from_bvh(*bvh, {});
  ASSERT_TRUE(motion.ok()) << motion.message();
  const ImportMeasures m = measure_import(*motion);
  EXPECT_TRUE(m.human);
  EXPECT_GT(m.standing_height, 1.2f);  // joints only: the head joint is below the top of the head
  EXPECT_LT(m.standing_height, 1.9f);
  EXPECT_GT(m.body_up, 0.9f);
  EXPECT_NEAR(m.floor, 0.0f, 0.15f);
  EXPECT_NEAR(m.root_speed, 1.6f, 0.4f);  // the README's 1.6 m/s walk
}

TEST(ImportCheck, WrongUnitsAreRefusedWithTheFix) {
  const Result<Database> metres = build_walk(R"({"metres_per_unit": 1})");
  ASSERT_FALSE(metres.ok());
  EXPECT_TRUE(contains(metres.message(), "16_23.bvh: implausible import: standing height 24.3 m, outside 0.5-2.5 m"))
      << metres.message();
  EXPECT_TRUE(contains(metres.message(), "set \"import\": {\"metres_per_unit\": 0.05644}")) << metres.message();
  EXPECT_TRUE(contains(metres.message(), "\"accept_implausible\": true")) << metres.message();
  const Result<Database> centimetres = build_walk(R"({"metres_per_unit": 0.01})");
  ASSERT_FALSE(centimetres.ok());
  EXPECT_TRUE(contains(centimetres.message(), "standing height 0.243 m")) << centimetres.message();
  EXPECT_TRUE(build_walk(R"({"metres_per_unit": 1, "accept_implausible": true})").ok());
  EXPECT_TRUE(build_walk(R"({"metres_per_unit": 0.05644})").ok());
}

TEST(ImportCheck, WrongUpAxisIsRefusedWithTheFix) {
  const Result<Database> z = build_walk(R"({"up_axis": "z"})");
  ASSERT_FALSE(z.ok());
  EXPECT_TRUE(contains(z.message(), "16_23.bvh: implausible import: the body is not upright along +Y")) << z.message();
  EXPECT_TRUE(contains(z.message(), "set \"import\": {\"up_axis\": \"y\"}")) << z.message();
  const Result<Database> accepted = build_walk(R"({"up_axis": "z", "accept_implausible": true})");
  EXPECT_TRUE(accepted.ok()) << accepted.message();
}

TEST(ImportCheck, WalkingTooFastIsRefused) {
  ImportMeasures m{.human = true, .standing_height = 1.7f, .floor = 0.0f, .body_up = 0.95f, .root_speed = 6.0f};
  ImportContext context;
  context.source = "w.bvh";
  context.units_from = "guessed";
  EXPECT_TRUE(check_import(m, context).ok());  // a sprint, untagged
  context.walk = true;
  const Status walk = check_import(m, context);
  ASSERT_FALSE(walk.ok());
  EXPECT_TRUE(contains(walk.message(), "the hips move at 6 m/s (the median over frames), faster than 4 m/s for a clip "
                                       "tagged \"walk\"")) << walk.message();
  m.human = false;  // not a person: nothing to compare with
  EXPECT_TRUE(check_import(m, context).ok());
}

TEST(ImportCheck, ShippedSetsBuild) {
  for (const char* set : {"cmu16/manifest.json", "cmu131/manifest.json"}) {
    const Result<Manifest> manifest = load_manifest(shipped(set));
    ASSERT_TRUE(manifest.ok()) << manifest.message();
    const Result<Database> database = build_database(*manifest);
    EXPECT_TRUE(database.ok()) << set << ": " << database.message();
  }
}

}  // namespace
}  // namespace mmvk
