// Walks the table of channel kinds: every entry is complete and consistent,
// its labels name exactly its dims, every kind round-trips through the
// schema JSON, names its missing fields, and extracts finite values.
#include <gtest/gtest.h>

#include <set>

#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/features/features.hpp"
#include "support/motion_fixtures.hpp"

namespace mmvk {
namespace {

// A channel of `info`'s kind with every field it reads filled in.
FeatureChannel sample_channel(const ChannelKindInfo& info) {
  FeatureChannel channel;
  channel.name = std::string(info.name) + "_channel";
  channel.kind = info.kind;
  if (has_field(info.fields, ChannelField::Bone)) channel.bone = "@left_foot";
  if (has_field(info.fields, ChannelField::SecondBone)) {
    // A second bone hangs below the first (limb_vector: the limb's end).
    channel.bone = "@left_upper_leg";
    channel.second_bone = "@left_foot";
  }
  if (has_field(info.fields, ChannelField::Curves)) {
    channel.curves = {"@left_foot.height", "@right_foot.speed"};
    channel.window_seconds = 0.25f;
  }
  if (has_field(info.fields, ChannelField::Offsets)) channel.offsets_seconds = {0.25f, 0.5f, 1.0f};
  if (has_field(info.fields, ChannelField::Dims)) channel.custom_dims = 4;
  channel.weight = 1.5f;
  channel.normalization = Normalization::MinMax;
  return channel;
}

TEST(ChannelKinds, EveryEntryIsCompleteAndFoundByName) {
  ASSERT_FALSE(channel_kinds().empty());
  std::set<std::string_view> names;
  for (std::size_t i = 0; i < channel_kinds().size(); ++i) {
    const ChannelKindInfo& info = channel_kinds()[i];
    SCOPED_TRACE(info.name);
    EXPECT_EQ(static_cast<std::size_t>(info.kind), i) << "the table is indexed by ChannelKind";
    EXPECT_EQ(&channel_kind_info(info.kind), &info);
    EXPECT_FALSE(info.name.empty());
    EXPECT_EQ(info.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string_view::npos)
        << "JSON names are snake_case";
    EXPECT_TRUE(names.insert(info.name).second) << "duplicate name";
    EXPECT_FALSE(info.summary.empty());
    EXPECT_NE(info.extract, nullptr);
    EXPECT_EQ(find_channel_kind(info.name), &info);
    EXPECT_EQ(channel_kind_name(info.kind), info.name);
    EXPECT_NE(channel_kind_list().find('"' + std::string(info.name) + '"'), std::string::npos);
  }
  EXPECT_EQ(find_channel_kind("hand"), nullptr);
}

TEST(ChannelKinds, RulesAgreeWithFields) {
  for (const ChannelKindInfo& info : channel_kinds()) {
    SCOPED_TRACE(info.name);
    // Offsets <=> one group of labels per offset; curves <=> one group per curve.
    EXPECT_EQ(has_field(info.fields, ChannelField::Offsets), info.dims_rule == DimsRule::LabelsPerOffset);
    EXPECT_EQ(has_field(info.fields, ChannelField::Curves), info.dims_rule == DimsRule::LabelsPerCurve);
    EXPECT_EQ(uses_trajectory_offsets(info.kind), has_field(info.fields, ChannelField::Offsets));
    // Declared width <=> sidecar values <=> no labels.
    EXPECT_EQ(has_field(info.fields, ChannelField::Dims), info.dims_rule == DimsRule::Declared);
    EXPECT_EQ(reads_sidecar(info.kind), info.dims_rule == DimsRule::Declared);
    EXPECT_EQ(info.labels.empty(), info.dims_rule == DimsRule::Declared);
    // A default bone only for kinds that read a bone; sidecar values cannot be remeasured.
    EXPECT_TRUE(info.default_bone.empty() || has_field(info.fields, ChannelField::Bone));
    EXPECT_TRUE(!reads_sidecar(info.kind) || info.mirror == MirrorRule::Unchanged);
  }
}

TEST(ChannelKinds, LabelsNameEveryDimOnce) {
  for (const ChannelKindInfo& info : channel_kinds()) {
    SCOPED_TRACE(info.name);
    const FeatureChannel channel = sample_channel(info);
    std::uint32_t expected = 0;
    switch (info.dims_rule) {
      case DimsRule::Labels: expected = static_cast<std::uint32_t>(info.labels.size()); break;
      case DimsRule::LabelsPerOffset: expected = static_cast<std::uint32_t>(3 * info.labels.size()); break;
      case DimsRule::Declared: expected = 4; break;
      case DimsRule::LabelsPerCurve: expected = static_cast<std::uint32_t>(2 * info.labels.size()); break;
    }
    ASSERT_EQ(channel.dims(), expected);
    ASSERT_GT(expected, 0u);
    // Behind another channel, so dim_name's offsets are exercised too.
    FeatureChannel first = sample_channel(channel_kind_info(ChannelKind::BonePosition));
    first.name = "first";
    FeatureSchema schema;
    schema.channels = {first, channel};
    ASSERT_TRUE(schema.validate().ok()) << schema.validate().message();
    std::set<std::string> dim_names;
    for (std::uint32_t d = schema.offset(1); d < schema.dims(); ++d) {
      const std::string name = schema.dim_name(d);
      EXPECT_EQ(name.rfind(channel.name, 0), 0u) << name;
      EXPECT_TRUE(dim_names.insert(name).second) << "duplicate dimension name " << name;
      if (info.labels.empty()) continue;
      const std::string label(info.labels[(d - schema.offset(1)) % info.labels.size()]);
      EXPECT_EQ(name.substr(name.size() - label.size() - 1), "." + label) << "labels repeat in order";
    }
    EXPECT_EQ(dim_names.size(), expected);
  }
}

TEST(ChannelKinds, EveryKindRoundTripsThroughJson) {
  for (const ChannelKindInfo& info : channel_kinds()) {
    SCOPED_TRACE(info.name);
    FeatureSchema schema;
    schema.channels = {sample_channel(info)};
    const std::string json = schema_to_json(schema);
    EXPECT_NE(json.find('"' + std::string(info.name) + '"'), std::string::npos) << json;
    Result<FeatureSchema> parsed = parse_schema_json(json, "kind.json");
    ASSERT_TRUE(parsed.ok()) << parsed.message() << "\n" << json;
    ASSERT_EQ(parsed->channels.size(), 1u);
    const FeatureChannel& a = schema.channels[0];
    const FeatureChannel& b = parsed->channels[0];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.kind, a.kind);
    EXPECT_EQ(b.bone, a.bone);
    EXPECT_EQ(b.second_bone, a.second_bone);
    EXPECT_EQ(b.offsets_seconds, a.offsets_seconds);
    EXPECT_EQ(b.custom_dims, a.custom_dims);
    EXPECT_EQ(b.curves, a.curves);
    EXPECT_EQ(b.window_seconds, a.window_seconds);
    EXPECT_EQ(b.weight, a.weight);
    EXPECT_EQ(b.normalization, a.normalization);
    EXPECT_EQ(parsed->dims(), schema.dims());
    EXPECT_EQ(schema_to_json(*parsed), json);
  }
}

TEST(ChannelKinds, MissingFieldsAreNamed) {
  for (const ChannelKindInfo& info : channel_kinds()) {
    SCOPED_TRACE(info.name);
    struct Case {
      ChannelField field;
      void (*clear)(FeatureChannel&);
      const char* message;
    };
    const Case cases[] = {
        {ChannelField::Bone, [](FeatureChannel& c) { c.bone.clear(); }, "bone is missing"},
        {ChannelField::SecondBone, [](FeatureChannel& c) { c.second_bone.clear(); }, "second_bone is missing"},
        {ChannelField::Offsets, [](FeatureChannel& c) { c.offsets_seconds.clear(); }, "offsets_seconds is empty"},
        {ChannelField::Dims, [](FeatureChannel& c) { c.custom_dims = 0; }, "dims must be > 0"},
        {ChannelField::Curves, [](FeatureChannel& c) { c.curves.clear(); }, "curves is empty"},
    };
    for (const Case& test : cases) {
      if (!has_field(info.fields, test.field)) continue;
      FeatureSchema schema;
      schema.channels = {sample_channel(info)};
      test.clear(schema.channels[0]);
      const Status status = schema.validate();
      if (test.field == ChannelField::Bone && !info.default_bone.empty()) {
        EXPECT_TRUE(status.ok()) << "the default bone " << info.default_bone << " applies";
        continue;
      }
      ASSERT_FALSE(status.ok()) << test.message;
      EXPECT_NE(status.message().find(test.message), std::string::npos) << status.message();
      EXPECT_NE(status.message().find(schema.channels[0].name), std::string::npos) << status.message();
    }
    if (!has_field(info.fields, ChannelField::SecondBone)) {
      const std::string json = R"({"channels": [{"name": "a", "kind": ")" + std::string(info.name) +
                               R"(", "second_bone": "@hips"}]})";
      Result<FeatureSchema> parsed = parse_schema_json(json, "s.json");
      ASSERT_FALSE(parsed.ok());
      EXPECT_NE(parsed.message().find("channels[0].second_bone: a " + std::string(info.name) + " channel reads no"),
                std::string::npos)
          << parsed.message();
    }
  }
}

TEST(ChannelKinds, EveryKindExtractsFiniteValuesInItsColumns) {
  // Walking 1.5 m/s, turning 0.6 rad/s, legs swinging 0.4 rad.
  const Motion motion = test::walker(40, 1.5f, 0.0f, 0.6f, 0.4f);
  Result<CharacterRoot> root = compute_character_root(motion, {});
  ASSERT_TRUE(root.ok()) << root.message();
  for (const ChannelKindInfo& info : channel_kinds()) {
    SCOPED_TRACE(info.name);
    // Between two bone channels, so a kind writing outside its columns shows.
    FeatureChannel before = sample_channel(channel_kind_info(ChannelKind::BonePosition));
    before.name = "before";
    FeatureChannel after = before;
    after.name = "after";
    FeatureSchema alone;
    alone.channels = {sample_channel(info)};
    FeatureSchema framed;
    framed.channels = {before, alone.channels[0], after};
    std::vector<std::vector<float>> custom;
    if (reads_sidecar(info.kind)) {
      custom.emplace_back(std::size_t{motion.frame_count} * alone.channels[0].custom_dims);
      for (std::size_t i = 0; i < custom[0].size(); ++i) custom[0][i] = 0.25f * float(i);
    }
    FeatureExtractionOptions options;
    options.custom = custom;
    Result<RawFeatures> one = extract_features(motion, *root, alone, options);
    ASSERT_TRUE(one.ok()) << one.message();
    Result<RawFeatures> three = extract_features(motion, *root, framed, options);
    ASSERT_TRUE(three.ok()) << three.message();
    Result<RawFeatures> bones = extract_features(motion, *root, FeatureSchema{{before}}, {});
    ASSERT_TRUE(bones.ok()) << bones.message();
    const std::uint32_t n = alone.dims();
    ASSERT_EQ(three->dims, n + 6);
    for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
      for (std::uint32_t d = 0; d < n; ++d) {
        ASSERT_EQ(three->values[std::size_t{f} * three->dims + 3 + d], one->values[std::size_t{f} * n + d]);
      }
      for (std::uint32_t d = 0; d < 3; ++d) {
        const float bone = bones->values[std::size_t{f} * 3 + d];
        ASSERT_EQ(three->values[std::size_t{f} * three->dims + d], bone);
        ASSERT_EQ(three->values[std::size_t{f} * three->dims + 3 + n + d], bone);
      }
    }
    EXPECT_EQ(one->past_end != std::vector<std::uint8_t>(motion.frame_count, 0), follows_edge_rule(info.kind))
        << "only kinds reading other frames (trajectory offsets, phase windows) run past a non-looping clip's edges";
  }
}

}  // namespace
}  // namespace mmvk
