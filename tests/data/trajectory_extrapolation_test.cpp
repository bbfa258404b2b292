// The Extrapolate edge rule on real takes: cut CMU takes short, extract the
// cut clip's features with the trajectory extrapolated, and compare the 1 s
// trajectory of its last second with the full take's, which knows where the
// character really went. This is how kExtrapolateSeconds was chosen (the
// shortest windows, the most recent speed and turning rate, predict best);
// the test keeps the choice honest.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/import/motion.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

constexpr float kFps = 30.0f;
constexpr std::uint32_t kSecond = 30;

// Frames [first, first + count) of a motion.
Motion cut(const Motion& motion, std::uint32_t first, std::uint32_t count) {
  Motion out;
  out.skeleton = motion.skeleton;
  out.fps = motion.fps;
  out.frame_count = count;
  const std::size_t joints = motion.joint_count();
  const auto begin = static_cast<std::ptrdiff_t>(first * joints);
  const auto end = static_cast<std::ptrdiff_t>((first + count) * joints);
  out.local_positions.assign(motion.local_positions.begin() + begin, motion.local_positions.begin() + end);
  out.local_rotations.assign(motion.local_rotations.begin() + begin, motion.local_rotations.begin() + end);
  return out;
}

// The take at 30 fps; `skip` source frames dropped first (cgspeed's T-pose).
Motion load_take(const std::filesystem::path& path, std::uint32_t skip) {
  Result<BvhFile> bvh = load_bvh(path);
  EXPECT_TRUE(bvh.ok()) << bvh.message();
  Result<Motion> motion = motion_from_bvh(*bvh, {});
  EXPECT_TRUE(motion.ok()) << motion.message();
  Motion source = cut(*motion, skip, motion->frame_count - skip);
  Result<Motion> resampled = resample(source, kFps);
  EXPECT_TRUE(resampled.ok()) << resampled.message();
  return std::move(*resampled);
}

// The 1 s trajectory position of every frame, from the clip's own features
// ([frames x 2]); `seconds` as FeatureExtractionOptions::extrapolate_seconds.
std::vector<float> one_second_ahead(const Motion& motion, float seconds) {
  const FeatureSchema schema = default_schema();
  std::uint32_t x = 0;
  while (schema.dim_name(x) != "trajectory_position[2].x") ++x;
  Result<CharacterRoot> root = compute_character_root(motion, {});
  EXPECT_TRUE(root.ok()) << root.message();
  FeatureExtractionOptions options;
  options.extrapolate_seconds = seconds;
  Result<RawFeatures> raw = extract_features(motion, *root, schema, options);
  EXPECT_TRUE(raw.ok()) << raw.message();
  std::vector<float> out;
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    out.push_back(raw->values[std::size_t{f} * raw->dims + x]);
    out.push_back(raw->values[std::size_t{f} * raw->dims + x + 1]);
  }
  return out;
}

// Cuts the take at every half second where the character walks or runs on
// for the next second (the real end of a take that stops is standing still,
// where every rule agrees), and measures the distance (m) between the cut
// clip's 1 s trajectory position and the full take's, which knows where the
// character went, over the last second before the cut. `seconds` 0:
// clamped (the Exclude and Clamp rules' values). Returns {sum, frames}.
std::pair<double, std::uint32_t> cut_errors(const Motion& full, float seconds) {
  const std::vector<float> truth = one_second_ahead(full, 0.0f);
  double sum = 0.0;
  std::uint32_t count = 0;
  for (std::uint32_t cut_at = kSecond; cut_at + kSecond <= full.frame_count; cut_at += kSecond / 2) {
    // Moving on: the true 1 s trajectory of the cut's frame is over 0.4 m away.
    if (std::hypot(truth[2 * (cut_at - 1)], truth[2 * (cut_at - 1) + 1]) < 0.4f) continue;
    const std::vector<float> guess = one_second_ahead(cut(full, 0, cut_at), seconds);
    for (std::uint32_t f = cut_at - kSecond; f < cut_at; ++f) {
      sum += std::hypot(double(truth[2 * f] - guess[2 * f]), double(truth[2 * f + 1] - guess[2 * f + 1]));
      ++count;
    }
  }
  return {sum, count};
}

TEST(TrajectoryExtrapolation, PredictsTheCutSecondOfCmuTakes) {
  MMVK_REQUIRE_DATA_DIR(data);
  struct Take {
    std::string file;
    std::uint32_t skip;
  };
  // The takes of at least 2 s (the subject 16 jogs and the run veer are
  // shorter), cgspeed's T-pose frame dropped; 131_01 and 131_02 start and
  // stop, the others walk curves.
  const std::vector<Take> takes = {
      {"cmu/cgspeed-16/16_23.bvh", 1},    {"cmu/cgspeed-16/16_27.bvh", 1},    {"cmu/cgspeed-16/16_57.bvh", 1},
      {"cmu/amc2bvh-131/131_01.bvh", 0}, {"cmu/amc2bvh-131/131_02.bvh", 0}, {"cmu/amc2bvh-131/131_09.bvh", 0}, {"cmu/amc2bvh-131/131_10.bvh", 0}, {"cmu/amc2bvh-131/131_11.bvh", 0},
      {"cmu/amc2bvh-131/131_12.bvh", 0}, {"cmu/amc2bvh-131/131_13.bvh", 0}, {"cmu/amc2bvh-131/131_14.bvh", 0}};
  const std::vector<float> windows = {0.0f, 1.0f / kFps, 0.25f, 0.5f, 1.0f, kExtrapolateSeconds};
  std::vector<double> sums(windows.size(), 0.0);
  std::uint32_t frames = 0;
  std::printf("per take, m over the last second before each cut: clamped; extrapolated over one "
              "frame, 0.25, 0.5, 1 s; kExtrapolateSeconds\n");
  for (const Take& take : takes) {
    const Motion motion = load_take(data / take.file, take.skip);
    ASSERT_GE(motion.frame_count, 2 * kSecond) << take.file;
    std::string line = take.file + ":";
    for (std::size_t w = 0; w < windows.size(); ++w) {
      const auto [sum, count] = cut_errors(motion, windows[w]);
      sums[w] += sum;
      if (w == 0) frames += count;
      char text[32];
      std::snprintf(text, sizeof(text), count ? " %.3f" : " -", count ? sum / count : 0.0);
      line += text;
    }
    std::printf("%s\n", line.c_str());
  }
  ASSERT_GT(frames, 300u);
  std::vector<double> totals;
  for (const double sum : sums) totals.push_back(sum / frames);
  std::printf("mean over %u frames: clamped %.3f m; extrapolated over one frame %.3f, 0.25 s %.3f, 0.5 s %.3f, 1 s %.3f; "
              "kExtrapolateSeconds (%.2f s) %.3f\n",
              frames, totals[0], totals[1], totals[2], totals[3], totals[4], double(kExtrapolateSeconds), totals[5]);
  const double chosen = totals.back();
  // Extrapolating beats clamping by far, and the chosen window is within 10%
  // of the best of those tried.
  EXPECT_LT(chosen, 0.5 * totals[0]);
  for (std::size_t w = 1; w + 1 < totals.size(); ++w) EXPECT_LE(chosen, 1.1 * totals[w]) << windows[w];
}

}  // namespace
}  // namespace mmvk
