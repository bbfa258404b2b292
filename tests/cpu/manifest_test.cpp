// The JSON manifest: every field, defaults, folders of BVH, and errors that
// name the manifest field at fault.
#include <gtest/gtest.h>

#include <fstream>

#include "mmvk/database/manifest.hpp"
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

TEST(Manifest, ContactsBlock) {
  Result<Manifest> manifest = parse_manifest_json(R"({
      "contacts": {"left_toe": "ToeL", "right_toe": "ToeR", "left_heel": "AnkleL", "right_heel": "AnkleR",
                   "enter_height": 0.01, "exit_height": 0.04, "enter_speed": 0.02, "exit_speed": 0.09,
                   "min_contact_seconds": 0.2, "min_gap_seconds": 0, "speed_step_seconds": 0.05,
                   "height_above_clip_floor": false, "floor_percentile": 0.1, "heel_height_extra": 0.07},
      "clips": ["a.bvh"]})",
                                                  "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  const FootContactParams& c = manifest->contacts;
  EXPECT_EQ(c.left_toe, "ToeL");
  EXPECT_EQ(c.right_toe, "ToeR");
  EXPECT_EQ(c.left_heel, "AnkleL");
  EXPECT_EQ(c.right_heel, "AnkleR");
  EXPECT_EQ(c.enter_height, 0.01f);
  EXPECT_EQ(c.exit_height, 0.04f);
  EXPECT_EQ(c.enter_speed, 0.02f);
  EXPECT_EQ(c.exit_speed, 0.09f);
  EXPECT_EQ(c.min_contact_seconds, 0.2f);
  EXPECT_EQ(c.min_gap_seconds, 0.0f);
  EXPECT_EQ(c.speed_step_seconds, 0.05f);
  EXPECT_FALSE(c.height_above_clip_floor);
  EXPECT_EQ(c.floor_percentile, 0.1f);
  EXPECT_EQ(c.heel_height_extra, 0.07f);

  // Fields left out keep the documented defaults.
  manifest = parse_manifest_json(R"({"contacts": {"exit_speed": 0.3}, "clips": ["a.bvh"]})", "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_EQ(manifest->contacts.exit_speed, 0.3f);
  EXPECT_EQ(manifest->contacts.enter_speed, FootContactParams{}.enter_speed);
  EXPECT_EQ(manifest->contacts.left_toe, "@left_toe");
}

TEST(Manifest, TheCrowdBlockIsKeptAsItsJsonText) {
  Result<Manifest> manifest =
      parse_manifest_json(R"({"crowd": {"correction_half_life": 0.07}, "clips": ["a.bvh"]})", "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_EQ(manifest->crowd, R"({"correction_half_life":0.07})");
  manifest = parse_manifest_json(R"({"clips": ["a.bvh"]})", "m.json", "/base");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  EXPECT_TRUE(manifest->crowd.empty());
  EXPECT_NE(manifest_error(R"({"crowd": [1], "clips": ["a.bvh"]})").find("m.json: crowd: expected an object"),
            std::string::npos);
}

TEST(Manifest, ContactsErrorsNameTheField) {
  const auto error = [](std::string_view contacts) {
    return manifest_error(std::string(R"({"contacts": )") + std::string(contacts) + R"(, "clips": ["a.bvh"]})");
  };
  EXPECT_NE(error("[]").find("m.json: contacts: expected an object"), std::string::npos);
  EXPECT_NE(error(R"({"max_speed": 1})").find("m.json: contacts.max_speed: unknown field"), std::string::npos);
  EXPECT_NE(error(R"({"enter_speed": -0.1})").find("m.json: contacts.enter_speed: must be a finite number >= 0, got -0.1"),
            std::string::npos);
  EXPECT_NE(error(R"({"exit_height": -1e-3})").find("m.json: contacts.exit_height: must be a finite number >= 0"),
            std::string::npos);
  // JSON has no NaN or infinity; a number beyond float's range is the way in.
  EXPECT_NE(error(R"({"min_gap_seconds": 1e39})").find("m.json: contacts.min_gap_seconds: not a finite number"),
            std::string::npos);
  EXPECT_NE(error(R"({"exit_speed": "fast"})").find("m.json: contacts.exit_speed: expected a number"), std::string::npos);
  EXPECT_NE(error(R"({"enter_speed": 0.2, "exit_speed": 0.1})")
                .find("m.json: contacts.exit_speed: must be >= enter_speed (0.2), got 0.1"),
            std::string::npos);
  EXPECT_NE(error(R"({"exit_height": 0.001})").find("m.json: contacts.exit_height: must be >= enter_height"),
            std::string::npos);
  EXPECT_NE(error(R"({"floor_percentile": 1.5})").find("m.json: contacts.floor_percentile: must be in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error(R"({"left_toe": ""})").find("m.json: contacts.left_toe: empty bone name"), std::string::npos);
  EXPECT_NE(error(R"({"right_heel": 3})").find("m.json: contacts.right_heel: expected a string"), std::string::npos);
  EXPECT_NE(error(R"({"height_above_clip_floor": 1})").find("m.json: contacts.height_above_clip_floor: expected true or false"),
            std::string::npos);
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

TEST(Manifest, OneBvhFileIsOneClipWithTheFolderDefaults) {
  const auto dir = test::make_temp_dir();
  std::ofstream(dir / "Walk.BVH") << "x";
  Result<Manifest> manifest = load_manifest_or_directory(dir / "Walk.BVH");
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  ASSERT_EQ(manifest->clips.size(), 1u);
  EXPECT_EQ(manifest->clips[0].file, dir / "Walk.BVH");
  EXPECT_EQ(manifest->clips[0].name, "Walk");
  EXPECT_EQ(manifest->schema.dims(), Manifest{}.schema.dims());
  // Any other file is read as a manifest, and its error says so.
  std::ofstream(dir / "walk.txt") << "x";
  Result<Manifest> other = load_manifest_or_directory(dir / "walk.txt");
  ASSERT_FALSE(other.ok());
  EXPECT_NE(other.message().find("walk.txt: not valid JSON"), std::string::npos) << other.message();
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
  EXPECT_NE(none.message().find("no motion files (.bvh"), std::string::npos);
  Result<Manifest> missing = load_manifest_or_directory(dir / "absent");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("absent"), std::string::npos);
}

}  // namespace
}  // namespace mmvk
