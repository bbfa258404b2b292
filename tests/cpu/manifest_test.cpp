// The JSON manifest: every field, defaults, folders of BVH, and errors that
// name the manifest field at fault.
#include <gtest/gtest.h>

#include <fstream>

#include "mmvk/manifest.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

std::string manifest_error(std::string_view json) {
  Result<Manifest> manifest = parse_manifest_json(json, "m.json", "/base");
  EXPECT_FALSE(manifest.ok()) << json;
  return manifest.ok() ? std::string() : manifest.message();
}

TEST(Manifest, ParsesEveryField) {
  Result<Manifest> manifest = parse_manifest_json(R"({
      "schema": {"channels": [{"name": "hipv", "kind": "root_velocity", "weight": 2}]},
      "fps": 60, "import": {"metres_per_unit": 0.01, "up_axis": "z"},
      "character_root": {"source_bone": "Hips", "facing_smoothing_seconds": 0.25},
      "edge_rule": "clamp",
      "clips": [
        {"file": "walk.bvh", "name": "w", "tags": ["walk", "loco", "walk"], "loop": true, "mirror": true,
         "cost_multiplier": 1.5, "cost_bias": -0.25, "do_not_use": [[0, 0.5]],
         "block_transition": [[1.0, 2.0], [3, 3.5]]},
        "sub/run.bvh",
        {"file": "/abs/turn.bvh"}]})",
                                                  "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_EQ(manifest->source, "m.json");
  ASSERT_EQ(manifest->schema.channels.size(), 1u);
  EXPECT_EQ(manifest->schema.channels[0].weight, 2.0f);
  EXPECT_EQ(manifest->fps, 60.0f);
  EXPECT_EQ(manifest->import.metres_per_unit, 0.01f);
  EXPECT_EQ(manifest->import.up_axis, UpAxis::Z);
  EXPECT_EQ(manifest->character_root.source_bone, "Hips");
  EXPECT_EQ(manifest->character_root.facing_smoothing_seconds, 0.25f);
  EXPECT_EQ(manifest->edge_rule, EdgeRule::Clamp);
  ASSERT_EQ(manifest->clips.size(), 3u);
  const ManifestClip& walk = manifest->clips[0];
  EXPECT_EQ(walk.file, std::filesystem::path("/base/walk.bvh"));
  EXPECT_EQ(walk.name, "w");
  EXPECT_EQ(walk.tags, (std::vector<std::string>{"walk", "loco"}));
  EXPECT_TRUE(walk.loop);
  EXPECT_TRUE(walk.mirror);
  EXPECT_EQ(walk.cost_multiplier, 1.5f);
  EXPECT_EQ(walk.cost_bias, -0.25f);
  ASSERT_EQ(walk.do_not_use.size(), 1u);
  EXPECT_EQ(walk.do_not_use[0].end_seconds, 0.5f);
  ASSERT_EQ(walk.block_transition.size(), 2u);
  EXPECT_EQ(walk.block_transition[1].begin_seconds, 3.0f);
  EXPECT_EQ(manifest->clips[1].file, std::filesystem::path("/base/sub/run.bvh"));
  EXPECT_EQ(manifest->clips[1].name, "run");
  EXPECT_FALSE(manifest->clips[1].mirror);
  EXPECT_EQ(manifest->clips[2].file, std::filesystem::path("/abs/turn.bvh"));
}

TEST(Manifest, ClipRange) {
  Result<Manifest> manifest =
      parse_manifest_json(R"({"clips": [{"file": "a.bvh", "range": [0.5, 1.4], "loop": true}, "b.bvh"]})", "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  ASSERT_TRUE(manifest->clips[0].range.has_value());
  EXPECT_EQ(manifest->clips[0].range->begin_seconds, 0.5f);
  EXPECT_EQ(manifest->clips[0].range->end_seconds, 1.4f);
  EXPECT_FALSE(manifest->clips[1].range.has_value());
  Result<Manifest> bad = parse_manifest_json(R"({"clips": [{"file": "a.bvh", "range": [2, 1]}]})", "m.json", "/base");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("m.json: clips[0].range: expected 0 <= begin < end"), std::string::npos) << bad.message();
}

TEST(Manifest, EdgeRulesByName) {
  for (const EdgeRule rule : {EdgeRule::Exclude, EdgeRule::Clamp, EdgeRule::Extrapolate}) {
    const std::string json =
        R"({"edge_rule": ")" + std::string(edge_rule_name(rule)) + R"(", "clips": ["a.bvh"]})";
    Result<Manifest> manifest = parse_manifest_json(json, "m.json", "/base");
    ASSERT_TRUE(manifest.ok()) << manifest.message();
    EXPECT_EQ(manifest->edge_rule, rule) << json;
  }
  EXPECT_EQ(edge_rule_name(EdgeRule::Extrapolate), "extrapolate");
  EXPECT_FALSE(parse_edge_rule("Clamp").ok());
}

TEST(Manifest, DefaultsAndMirrorAll) {
  Result<Manifest> manifest = parse_manifest_json(R"({"mirror": true, "clips": ["a.bvh"]})", "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_EQ(manifest->schema.dims(), 27u);
  EXPECT_EQ(manifest->fps, 0.0f);
  EXPECT_EQ(manifest->edge_rule, EdgeRule::Exclude);
  EXPECT_EQ(manifest->import.metres_per_unit, 0.0f);
  EXPECT_EQ(manifest->character_root.source_bone, "@hips");
  ASSERT_EQ(manifest->clips.size(), 1u);
  EXPECT_TRUE(manifest->clips[0].mirror);
  EXPECT_FALSE(manifest->clips[0].loop);
  EXPECT_EQ(manifest->clips[0].cost_multiplier, 1.0f);
  EXPECT_EQ(manifest->clips[0].cost_bias, 0.0f);
}

TEST(Manifest, ErrorsNameTheField) {
  EXPECT_NE(manifest_error("{").find("m.json: not valid JSON"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"clip": []})").find("m.json: clip: unknown field"), std::string::npos);
  EXPECT_NE(manifest_error(R"({})").find("m.json: clips: expected an array"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": []})").find("m.json: clips: empty"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "loops": true}]})").find("m.json: clips[0].loops: unknown field"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": ["a.bvh", {"file": "b.bvh", "loop": 1}]})").find("m.json: clips[1].loop: expected true or false"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"name": "x"}]})").find("clips[0].file: missing"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "cost_multiplier": 0}]})").find("clips[0].cost_multiplier: must be > 0"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "cost_bias": "big"}]})").find("clips[0].cost_bias: expected a number"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "tags": ["a", 3]}]})").find("clips[0].tags[1]: expected a string"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "do_not_use": [[0, 1], [2, 1]]}]})").find("clips[0].do_not_use[1]: expected 0 <= begin < end"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"clips": [{"file": "a.bvh", "block_transition": [[0, 1, 2]]}]})").find("clips[0].block_transition[0]"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"edge_rule": "wrap", "clips": ["a.bvh"]})").find("m.json: edge_rule: expected \"exclude\", \"clamp\", \"extrapolate\", got \"wrap\""),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"fps": -30, "clips": ["a.bvh"]})").find("m.json: fps"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"import": {"up_axis": "x"}, "clips": ["a.bvh"]})").find("m.json: import.up_axis"), std::string::npos);
  EXPECT_NE(manifest_error(R"({"import": {"units": 1}, "clips": ["a.bvh"]})").find("m.json: import.units: unknown field"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"character_root": {"facing_smoothing_seconds": -1}, "clips": ["a.bvh"]})")
                .find("character_root.facing_smoothing_seconds"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"schema": {"channels": [{"name": "a", "kind": "nope"}]}, "clips": ["a.bvh"]})")
                .find("m.json: schema: channels[0].kind"),
            std::string::npos);
  EXPECT_NE(manifest_error(R"({"schema": "missing.json", "clips": ["a.bvh"]})").find("missing.json"), std::string::npos);
}

TEST(Manifest, LoadsSchemaFilesRelativeToTheManifest) {
  const auto dir = test::make_temp_dir();
  {
    std::ofstream(dir / "s.json") << R"({"channels": [{"name": "hv", "kind": "root_velocity"}]})";
    std::ofstream(dir / "m.json") << R"({"schema": "s.json", "clips": ["walk.bvh"]})";
  }
  Result<Manifest> manifest = load_manifest_or_directory(dir / "m.json");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_EQ(manifest->schema.dims(), 3u);
  EXPECT_EQ(manifest->clips[0].file, dir / "walk.bvh");
}

TEST(Manifest, FolderOfBvhUsesDefaults) {
  const auto dir = test::make_temp_dir();
  std::ofstream(dir / "b.bvh") << "x";
  std::ofstream(dir / "A.BVH") << "x";
  std::ofstream(dir / "notes.txt") << "x";
  std::filesystem::create_directory(dir / "sub.bvh");
  Result<Manifest> manifest = load_manifest_or_directory(dir);
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  ASSERT_EQ(manifest->clips.size(), 2u);
  EXPECT_EQ(manifest->clips[0].name, "A");
  EXPECT_EQ(manifest->clips[1].name, "b");
  EXPECT_EQ(manifest->schema.dims(), 27u);

  const auto empty = dir / "empty";
  std::filesystem::create_directory(empty);
  Result<Manifest> none = load_manifest_or_directory(empty);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.message().find("no .bvh files"), std::string::npos);
  Result<Manifest> missing = load_manifest_or_directory(dir / "absent");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("absent"), std::string::npos);
}

}  // namespace
}  // namespace mmvk
