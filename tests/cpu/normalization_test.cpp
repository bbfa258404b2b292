// Normalization modes: after normalization each channel has mean ~0 (min 0
// for min-max) and a spread equal to its weight, since scale = spread / weight.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mmvk/features/normalization.hpp"

namespace mmvk {
namespace {

FeatureChannel channel(std::string name, Normalization mode, float weight) {
  FeatureChannel c;
  c.name = std::move(name);
  c.kind = ChannelKind::BonePosition;
  c.bone = "Hips";
  c.weight = weight;
  c.normalization = mode;
  return c;
}

FeatureSchema four_mode_schema() {
  FeatureSchema schema;
  schema.channels = {channel("group", Normalization::GroupStd, 2.0f), channel("perdim", Normalization::PerDimStd, 0.5f),
                     channel("mad", Normalization::MeanAbsDev, 1.5f), channel("minmax", Normalization::MinMax, 3.0f)};
  return schema;
}

// Each dim gets its own mean and spread so per-dim and group modes differ.
std::vector<float> random_features(std::uint32_t frames, std::uint32_t dims, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  std::vector<float> values(std::size_t{frames} * dims);
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (std::uint32_t d = 0; d < dims; ++d) values[std::size_t{f} * dims + d] = 10.0f * float(d) - 7.0f + (0.1f + float(d)) * normal(rng);
  }
  return values;
}

TEST(Normalization, EveryModeGivesMeanZeroAndSpreadEqualToTheWeight) {
  const FeatureSchema schema = four_mode_schema();
  const std::uint32_t dims = schema.dims();
  std::vector<float> values = random_features(5000, dims, 1234);
  Result<std::vector<DimNormalization>> normalization = compute_normalization(schema, values);
  ASSERT_TRUE(normalization.ok()) << normalization.message();
  apply_normalization(*normalization, values);
  const std::vector<DimStatistics> stats = compute_statistics(values, dims);
  // group: per-dim means 0, mean of per-dim std == weight.
  double group_spread = 0.0;
  for (std::uint32_t d = 0; d < 3; ++d) {
    EXPECT_NEAR(stats[d].mean, 0.0, 1e-4);
    group_spread += stats[d].std / 3.0;
  }
  EXPECT_NEAR(group_spread, 2.0, 1e-4);
  EXPECT_GT(std::abs(stats[0].std - stats[2].std), 0.1) << "group mode must keep the dims' relative spreads";
  for (std::uint32_t d = 3; d < 6; ++d) {
    EXPECT_NEAR(stats[d].mean, 0.0, 1e-4);
    EXPECT_NEAR(stats[d].std, 0.5, 1e-4);
  }
  for (std::uint32_t d = 6; d < 9; ++d) {
    EXPECT_NEAR(stats[d].mean, 0.0, 1e-4);
    EXPECT_NEAR(stats[d].mean_abs_dev, 1.5, 1e-4);
  }
  for (std::uint32_t d = 9; d < 12; ++d) {
    EXPECT_NEAR(stats[d].min, 0.0, 1e-5);
    EXPECT_NEAR(stats[d].max, 3.0, 1e-5);
  }
}

TEST(Normalization, ScaleIsSpreadOverWeight) {
  FeatureSchema schema;
  schema.channels = {channel("a", Normalization::PerDimStd, 4.0f)};
  // Dim x: values 1 and 3 -> mean 2, std 1.
  const std::vector<float> values = {1.0f, 0.0f, 5.0f, 3.0f, 2.0f, 9.0f};
  Result<std::vector<DimNormalization>> n = compute_normalization(schema, values);
  ASSERT_TRUE(n.ok()) << n.message();
  EXPECT_FLOAT_EQ((*n)[0].offset, 2.0f);
  EXPECT_FLOAT_EQ((*n)[0].scale, 0.25f);
  EXPECT_FLOAT_EQ((*n)[2].offset, 7.0f);
  EXPECT_FLOAT_EQ((*n)[2].scale, 0.5f);
}

TEST(Normalization, ZeroSpreadIsAnErrorNamingTheChannel) {
  const FeatureSchema schema = four_mode_schema();
  const std::uint32_t dims = schema.dims();
  for (std::uint32_t constant_dim : {0u, 4u, 7u, 11u}) {
    SCOPED_TRACE(constant_dim);
    std::vector<float> values = random_features(200, dims, 7);
    for (std::size_t f = 0; f < 200; ++f) values[f * dims + constant_dim] = 3.25f;
    Result<std::vector<DimNormalization>> n = compute_normalization(schema, values);
    if (constant_dim == 0) {
      // One constant dim in a group channel is fine: the group spread is the mean.
      EXPECT_TRUE(n.ok()) << n.message();
      continue;
    }
    ASSERT_FALSE(n.ok());
    EXPECT_NE(n.message().find("zero spread"), std::string::npos) << n.message();
    EXPECT_NE(n.message().find("'" + schema.channels[constant_dim / 3].name + "'"), std::string::npos) << n.message();
    EXPECT_NE(n.message().find(schema.dim_name(constant_dim)), std::string::npos) << n.message();
  }
  // A whole group constant, and float noise around a constant.
  std::vector<float> values = random_features(200, dims, 9);
  for (std::size_t f = 0; f < 200; ++f) {
    for (std::uint32_t d = 0; d < 3; ++d) values[f * dims + d] = 100.0f + (f % 2 ? 1e-6f : 0.0f);
  }
  Result<std::vector<DimNormalization>> n = compute_normalization(schema, values);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.message().find("channel 'group' has zero spread"), std::string::npos) << n.message();
}

// A schema weight of 1e38 or more (the scale spread / weight underflows to a
// denormal) made the normalized features infinite; the build then named a
// frame's feature, not the weight.
TEST(Normalization, AWeightThatOverflowsTheFeaturesIsNamed) {
  FeatureSchema schema;
  schema.channels = {channel("hips", Normalization::PerDimStd, 3e38f)};
  const std::vector<float> values = random_features(50, 3, 3);
  Result<std::vector<DimNormalization>> n = compute_normalization(schema, values);
  ASSERT_FALSE(n.ok());
  EXPECT_NE(n.message().find("channel 'hips': weight 3e+38 scales its features beyond float's range"),
            std::string::npos)
      << n.message();
  schema.channels[0].weight = 1e30f;  // large, but its features stay finite
  EXPECT_TRUE(compute_normalization(schema, values).ok());
}

TEST(Normalization, RejectsAMatrixOfTheWrongShape) {
  const FeatureSchema schema = four_mode_schema();
  std::vector<float> values(13, 1.0f);
  EXPECT_FALSE(compute_normalization(schema, values).ok());
  EXPECT_FALSE(compute_normalization(schema, {}).ok());
}

// The table of modes: every entry is found by its name, in enum order, and
// survives the schema's JSON form.
TEST(Normalization, EveryModeInTheTableRoundTripsThroughJson) {
  ASSERT_FALSE(normalization_modes().empty());
  for (std::size_t i = 0; i < normalization_modes().size(); ++i) {
    const NormalizationInfo& info = normalization_modes()[i];
    SCOPED_TRACE(info.name);
    EXPECT_EQ(static_cast<std::size_t>(info.mode), i);
    EXPECT_EQ(&normalization_info(info.mode), &info);
    EXPECT_EQ(find_normalization(info.name), &info);
    EXPECT_EQ(normalization_name(info.mode), info.name);
    EXPECT_FALSE(info.spread_name.empty());
    EXPECT_NE(normalization_list().find('"' + std::string(info.name) + '"'), std::string::npos);
    FeatureSchema schema;
    schema.channels = {channel("c", info.mode, 1.0f)};
    Result<FeatureSchema> parsed = parse_schema_json(schema_to_json(schema), "modes.json");
    ASSERT_TRUE(parsed.ok()) << parsed.message();
    EXPECT_EQ(parsed->channels[0].normalization, info.mode);
  }
  EXPECT_EQ(find_normalization("zscore"), nullptr);
}

}  // namespace
}  // namespace mmvk
