// The feature schema's JSON form: round trip and errors naming the field.
#include <gtest/gtest.h>

#include <fstream>

#include "mmvk/features/feature_schema.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

void expect_same(const FeatureSchema& a, const FeatureSchema& b) {
  ASSERT_EQ(a.channels.size(), b.channels.size());
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    SCOPED_TRACE(a.channels[c].name);
    EXPECT_EQ(a.channels[c].name, b.channels[c].name);
    EXPECT_EQ(a.channels[c].kind, b.channels[c].kind);
    EXPECT_EQ(a.channels[c].bone, b.channels[c].bone);
    EXPECT_EQ(a.channels[c].offsets_seconds, b.channels[c].offsets_seconds);  // bit-exact floats
    EXPECT_EQ(a.channels[c].custom_dims, b.channels[c].custom_dims);
    EXPECT_EQ(a.channels[c].weight, b.channels[c].weight);
    EXPECT_EQ(a.channels[c].normalization, b.channels[c].normalization);
  }
}

std::string parse_error(std::string_view json) {
  Result<FeatureSchema> schema = parse_schema_json(json, "s.json");
  EXPECT_FALSE(schema.ok()) << json;
  return schema.ok() ? std::string() : schema.message();
}

TEST(SchemaJson, DefaultSchemaHas27DimsAndRoundTrips) {
  const FeatureSchema schema = default_schema();
  EXPECT_EQ(schema.dims(), 27u);
  Result<FeatureSchema> parsed = parse_schema_json(schema_to_json(schema), "default");
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  expect_same(schema, *parsed);
}

TEST(SchemaJson, ParsesEveryKindAndMode) {
  Result<FeatureSchema> schema = parse_schema_json(R"({"channels": [
      {"name": "traj", "kind": "trajectory_position", "offsets_seconds": [0.2, 0.4], "weight": 2.5,
       "normalization": "per_dim_std"},
      {"name": "dir", "kind": "trajectory_direction", "offsets_seconds": [0.5], "normalization": "min_max"},
      {"name": "foot", "kind": "bone_position", "bone": "@left_foot", "dims": 3, "normalization": "mean_abs_dev"},
      {"name": "footv", "kind": "bone_velocity", "bone": "Foot_R"},
      {"name": "hipv", "kind": "root_velocity"},
      {"name": "phase", "kind": "custom", "dims": 2, "normalization": "group_std", "weight": 0.5}]})",
                                                   "s.json");
  ASSERT_TRUE(schema.ok()) << schema.message();
  EXPECT_EQ(schema->dims(), 4u + 2u + 3u + 3u + 3u + 2u);
  EXPECT_EQ(schema->channels[0].weight, 2.5f);
  EXPECT_EQ(schema->channels[0].normalization, Normalization::PerDimStd);
  EXPECT_EQ(schema->channels[1].normalization, Normalization::MinMax);
  EXPECT_EQ(schema->channels[2].normalization, Normalization::MeanAbsDev);
  EXPECT_EQ(schema->channels[3].normalization, Normalization::GroupStd);
  EXPECT_EQ(schema->channels[5].kind, ChannelKind::Custom);
  EXPECT_EQ(schema->channels[5].custom_dims, 2u);
  EXPECT_EQ(schema->offset(5), 15u);
  EXPECT_EQ(schema->dim_name(1), "traj[0].z");
  Result<FeatureSchema> again = parse_schema_json(schema_to_json(*schema), "again");
  ASSERT_TRUE(again.ok()) << again.message();
  expect_same(*schema, *again);
}

TEST(SchemaJson, ErrorsNameTheField) {
  EXPECT_NE(parse_error("{").find("s.json: not valid JSON"), std::string::npos);
  EXPECT_NE(parse_error("[]").find("s.json"), std::string::npos);
  EXPECT_NE(parse_error(R"({"chanels": []})").find("chanels: unknown field"), std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": {}})").find("channels"), std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": []})").find("no channels"), std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "root_velocity", "weigth": 2}]})")
                .find("channels[0].weigth: unknown field"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "hand"}]})").find("channels[0].kind: unknown kind \"hand\""),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"kind": "root_velocity"}]})").find("channels[0].name"), std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "root_velocity"}, {"name": "b", "kind": "root_velocity", "weight": "x"}]})")
                .find("channels[1].weight: expected a number"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "root_velocity", "weight": -1}]})").find("weight"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "trajectory_position"}]})").find("offsets_seconds is empty"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "trajectory_position", "offsets_seconds": [0.5, "x"]}]})")
                .find("channels[0].offsets_seconds[1]"),
            std::string::npos);
  // Issue 12 made negative offsets the past trajectory; 0 stays an error.
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "trajectory_position", "offsets_seconds": [0.0]}]})")
                .find("offsets_seconds must be finite and != 0"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "bone_position", "bone": "Hips", "dims": 2}]})")
                .find("channels[0].dims: a bone_position channel has 3 dims, not 2"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "bone_position"}]})").find("bone is missing"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "custom"}]})").find("dims must be > 0"), std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "custom", "dims": 0}]})").find("channels[0].dims"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "root_velocity", "normalization": "zscore"}]})")
                .find("channels[0].normalization: expected one of"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"channels": [{"name": "a", "kind": "root_velocity"}, {"name": "a", "kind": "root_velocity"}]})")
                .find("duplicate name"),
            std::string::npos);
}

TEST(SchemaJson, LoadsFromFileAndNamesMissingFiles) {
  const auto dir = test::make_temp_dir();
  {
    std::ofstream out(dir / "schema.json");
    out << schema_to_json(default_schema());
  }
  Result<FeatureSchema> loaded = load_schema(dir / "schema.json");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->dims(), 27u);
  Result<FeatureSchema> missing = load_schema(dir / "nope.json");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("nope.json"), std::string::npos);
}

}  // namespace
}  // namespace mmvk
