// Import on the real motion capture in ../shared/data (MMVK_DATA): every file
// parses with the manifest's frame count, FK keeps bone lengths, the two CMU
// 131_01 conversions agree, mirroring is an involution, Bandai's hips and
// character root are found, and a straight walk moves forward at walking speed.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/import/motion.hpp"
#include "support/test_data.hpp"

namespace {

namespace fs = std::filesystem;
using mmvk::Motion;

struct ManifestRow {
  int joints = 0;
  int channels = 0;
  int frames = 0;
  float fps = 0.0f;
};

// manifest.tsv: a header line, then one row per BVH file (tab-separated).
std::map<std::string, ManifestRow> read_manifest(const fs::path& path) {
  std::map<std::string, ManifestRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  {
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, '\t')) header.push_back(field);
  }
  const auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::size_t path_col = column("path");
  const std::size_t joints_col = column("joints");
  const std::size_t channels_col = column("channels");
  const std::size_t frames_col = column("frames");
  const std::size_t fps_col = column("fps");
  while (std::getline(in, line)) {
    std::vector<std::string> fields;
    std::stringstream stream(line);
    std::string field;
    while (std::getline(stream, field, '\t')) fields.push_back(field);
    if (fields.size() < header.size()) continue;
    rows[fields[path_col]] = ManifestRow{std::stoi(fields[joints_col]), std::stoi(fields[channels_col]),
                                         std::stoi(fields[frames_col]), std::stof(fields[fps_col])};
  }
  return rows;
}

Motion load_motion(const fs::path& path) {
  const auto file = mmvk::load_bvh(path);
  EXPECT_TRUE(file.ok()) << file.message();
  if (!file.ok()) return {};
  auto motion = mmvk::motion_from_bvh(*file, {});
  EXPECT_TRUE(motion.ok()) << motion.message();
  return motion.ok() ? std::move(motion).value() : Motion{};
}

// Model-space joint positions, [frame_count x joints].
std::vector<glm::vec3> global_positions(const Motion& motion) {
  std::vector<glm::vec3> positions(motion.frame_count * motion.joint_count());
  std::vector<glm::quat> rotations(positions.size());
  mmvk::forward_kinematics_clip(motion, positions, rotations);
  return positions;
}

int bone(const Motion& motion, const char* role) {
  const auto index = mmvk::find_bone(motion.skeleton, role);
  EXPECT_TRUE(index.ok()) << index.message();
  return index.ok() ? *index : 0;
}

const char* kBandaiWalk = "bandai-namco-nc/locomotion-normal/dataset-2_walk_normal_001.bvh";

TEST(ImportData, EveryFileParsesWithTheManifestFrameCount) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const auto manifest = read_manifest(dir / "manifest.tsv");
  ASSERT_GT(manifest.size(), 100u);
  std::set<std::string> seen;
  long total_frames = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    const fs::path relative = fs::relative(entry.path(), dir);
    // volume/ holds the benchmark archives (and whatever was unpacked there).
    if (std::find(relative.begin(), relative.end(), fs::path("volume")) != relative.end()) continue;
    if (!entry.is_regular_file() || entry.path().extension() != ".bvh") continue;
    const std::string key = relative.generic_string();
    SCOPED_TRACE(key);
    const auto it = manifest.find(key);
    ASSERT_NE(it, manifest.end()) << "not in manifest.tsv";
    seen.insert(key);
    const auto file = mmvk::load_bvh(entry.path());
    ASSERT_TRUE(file.ok()) << file.message();
    EXPECT_EQ(file->frame_count, it->second.frames);
    EXPECT_EQ(file->channel_count, it->second.channels);
    EXPECT_EQ(static_cast<int>(file->joints.size()), it->second.joints);
    const auto motion = mmvk::motion_from_bvh(*file, {});
    ASSERT_TRUE(motion.ok()) << motion.message();
    EXPECT_FLOAT_EQ(motion->fps, it->second.fps);
    EXPECT_EQ(motion->frame_count, static_cast<std::uint32_t>(it->second.frames));
    total_frames += file->frame_count;
  }
  EXPECT_EQ(seen.size(), manifest.size()) << "manifest rows without a file";
  EXPECT_GT(total_frames, 50000);
}

TEST(ImportData, LineEndingVariantsParseIdentically) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const auto lf = mmvk::load_bvh(dir / "tiny/cmu_max_131_01_head60_lf.bvh");
  const auto crlf = mmvk::load_bvh(dir / "tiny/cmu_max_131_01_head60_crlf.bvh");
  const auto mixed = mmvk::load_bvh(dir / "tiny/cmu_max_131_01_head60_mixed_eol.bvh");
  const auto full = mmvk::load_bvh(dir / "cmu/cgspeed-max/131_01.bvh");
  ASSERT_TRUE(lf.ok() && crlf.ok() && mixed.ok() && full.ok());
  EXPECT_EQ(lf->values, crlf->values);
  EXPECT_EQ(lf->values, mixed->values);
  ASSERT_EQ(lf->joints.size(), mixed->joints.size());
  for (std::size_t j = 0; j < lf->joints.size(); ++j) {
    EXPECT_EQ(lf->joints[j].name, mixed->joints[j].name);
    EXPECT_EQ(lf->joints[j].offset, crlf->joints[j].offset);
  }
  // The excerpt is frames 200-259 of the full take.
  const std::size_t columns = static_cast<std::size_t>(full->channel_count);
  ASSERT_EQ(lf->values.size(), 60 * columns);
  EXPECT_TRUE(std::equal(lf->values.begin(), lf->values.end(), full->values.begin() + 200 * columns));
}

TEST(ImportData, UnitsAreGuessedPerSource) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const std::map<std::string, float> expected{
      {"cmu/amc2bvh-131/131_01.bvh", 0.05644f}, {"cmu/cgspeed-max/131_01.bvh", 0.05644f},
      {"cmu/cgspeed-mb/01_01.bvh", 0.05644f},   {"cmu/cgspeed-daz/02_01.bvh", 0.01f},
      {kBandaiWalk, 0.01f},
  };
  for (const auto& [path, unit] : expected) {
    const auto file = mmvk::load_bvh(dir / path);
    ASSERT_TRUE(file.ok()) << file.message();
    EXPECT_EQ(mmvk::guess_metres_per_unit(*file), unit) << path;
    // A standing adult: the head well above the feet, in metres.
    const Motion motion = load_motion(dir / path);
    const auto positions = global_positions(motion);
    const glm::vec3 head = positions[static_cast<std::size_t>(bone(motion, "@head"))];
    const glm::vec3 foot = positions[static_cast<std::size_t>(bone(motion, "@left_foot"))];
    EXPECT_GT(head.y - foot.y, 1.2f) << path;
    EXPECT_LT(head.y - foot.y, 1.9f) << path;
  }
}

TEST(ImportData, BoneLengthsStayConstantUnderFk) {
  MMVK_REQUIRE_DATA_DIR(dir);
  for (const char* path : {"cmu/amc2bvh-131/131_01.bvh", "cmu/cgspeed-max/94_01.bvh", "cmu/cgspeed-mb/01_01.bvh",
                           "cmu/cgspeed-daz/02_01.bvh", kBandaiWalk,
                           "bandai-namco-nc/locomotion-normal/dataset-2_run_normal_001.bvh"}) {
    SCOPED_TRACE(path);
    const Motion motion = load_motion(dir / path);
    ASSERT_GT(motion.frame_count, 1u);
    const auto positions = global_positions(motion);
    const std::size_t joints = motion.joint_count();
    float worst = 0.0f;
    std::size_t bones = 0;
    for (std::size_t j = 0; j < joints; ++j) {
      const int parent = motion.skeleton.parents[j];
      if (parent < 0) continue;
      // A joint with animated translation (Bandai's Hips under the static
      // joint_Root) is not a bone.
      bool animated = false;
      for (std::uint32_t f = 1; f < motion.frame_count; ++f) {
        animated = animated || motion.local_positions[motion.index(f, j)] != motion.local_positions[j];
      }
      if (animated) continue;
      ++bones;
      const float rest = glm::length(positions[j] - positions[static_cast<std::size_t>(parent)]);
      for (std::uint32_t f = 1; f < motion.frame_count; ++f) {
        const float length =
            glm::length(positions[f * joints + j] - positions[f * joints + static_cast<std::size_t>(parent)]);
        worst = std::max(worst, std::abs(length - rest));
      }
    }
    EXPECT_LT(worst, 1e-4f) << "metres";
    EXPECT_GE(bones + 2, joints) << "at most the root and one translated joint are skipped";
  }
}

TEST(ImportData, BandaiPositionChannelsReplaceTheOffset) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Motion motion = load_motion(dir / kBandaiWalk);
  const auto positions = global_positions(motion);
  // Adding channels to OFFSETs would put the hips near 1.9 m and the head at 2.7 m.
  const glm::vec3 hips = positions[static_cast<std::size_t>(bone(motion, "@hips"))];
  const glm::vec3 head = positions[static_cast<std::size_t>(bone(motion, "@head"))];
  const glm::vec3 toe = positions[static_cast<std::size_t>(bone(motion, "@left_toe"))];
  EXPECT_GT(hips.y, 0.8f);
  EXPECT_LT(hips.y, 1.1f);
  EXPECT_GT(head.y, 1.4f);
  EXPECT_LT(head.y, 1.8f);
  EXPECT_LT(toe.y, 0.15f);
}

TEST(ImportData, Cmu131ConversionsGiveTheSameLegSegments) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Motion asf = load_motion(dir / "cmu/amc2bvh-131/131_01.bvh");
  const Motion cgspeed = load_motion(dir / "cmu/cgspeed-max/131_01.bvh");
  ASSERT_EQ(asf.frame_count, 994u);
  ASSERT_EQ(cgspeed.frame_count, asf.frame_count);
  EXPECT_EQ(asf.skeleton.names[static_cast<std::size_t>(bone(asf, "@left_upper_leg"))], "lfemur");
  EXPECT_EQ(cgspeed.skeleton.names[static_cast<std::size_t>(bone(cgspeed, "@left_upper_leg"))], "LeftHip");
  const auto pa = global_positions(asf);
  const auto pb = global_positions(cgspeed);
  // hip -> knee -> ankle -> toe, both sides.
  const char* chain[2][4] = {{"@left_upper_leg", "@left_lower_leg", "@left_foot", "@left_toe"},
                             {"@right_upper_leg", "@right_lower_leg", "@right_foot", "@right_toe"}};
  float worst = 0.0f;
  float shortest = 1e9f;
  for (const auto& side : chain) {
    for (int s = 0; s < 3; ++s) {
      const std::size_t a0 = static_cast<std::size_t>(bone(asf, side[s]));
      const std::size_t a1 = static_cast<std::size_t>(bone(asf, side[s + 1]));
      const std::size_t b0 = static_cast<std::size_t>(bone(cgspeed, side[s]));
      const std::size_t b1 = static_cast<std::size_t>(bone(cgspeed, side[s + 1]));
      for (std::uint32_t f = 0; f < asf.frame_count; ++f) {
        const glm::vec3 va = pa[f * asf.joint_count() + a1] - pa[f * asf.joint_count() + a0];
        const glm::vec3 vb = pb[f * cgspeed.joint_count() + b1] - pb[f * cgspeed.joint_count() + b0];
        worst = std::max(worst, glm::length(va - vb));
        shortest = std::min(shortest, glm::length(va));
      }
    }
  }
  EXPECT_GT(shortest, 0.05f) << "segments must be real bones, in metres";
  EXPECT_LT(worst, 1e-3f) << "metres";
}

TEST(ImportData, MirrorTwiceIsTheIdentityAndSwapsFeet) {
  MMVK_REQUIRE_DATA_DIR(dir);
  for (const char* path : {"cmu/amc2bvh-131/131_01.bvh", "cmu/cgspeed-mb/01_01.bvh", "cmu/cgspeed-daz/02_01.bvh",
                           kBandaiWalk}) {
    SCOPED_TRACE(path);
    const Motion motion = load_motion(dir / path);
    const auto mirrored = mmvk::mirror(motion);
    ASSERT_TRUE(mirrored.ok()) << mirrored.message();
    const auto back = mmvk::mirror(*mirrored);
    ASSERT_TRUE(back.ok()) << back.message();
    EXPECT_TRUE(back->local_positions == motion.local_positions);
    EXPECT_TRUE(back->local_rotations == motion.local_rotations);

    // The mirrored left foot is where the original right foot was, reflected.
    const auto original = global_positions(motion);
    const auto reflected = global_positions(*mirrored);
    const std::size_t left = static_cast<std::size_t>(bone(motion, "@left_foot"));
    const std::size_t right = static_cast<std::size_t>(bone(motion, "@right_foot"));
    const std::size_t joints = motion.joint_count();
    float worst = 0.0f;
    for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
      const glm::vec3 expected_left = original[f * joints + right] * glm::vec3(-1.0f, 1.0f, 1.0f);
      const glm::vec3 expected_right = original[f * joints + left] * glm::vec3(-1.0f, 1.0f, 1.0f);
      worst = std::max(worst, glm::length(reflected[f * joints + left] - expected_left));
      worst = std::max(worst, glm::length(reflected[f * joints + right] - expected_right));
    }
    EXPECT_LT(worst, 1e-4f) << "metres";
  }
}

// Every frame's joint positions relative to the root (its local transform
// set to the identity), [frame_count x joints].
std::vector<glm::vec3> root_relative_positions(Motion motion) {
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    motion.local_positions[motion.index(f, 0)] = glm::vec3(0.0f);
    motion.local_rotations[motion.index(f, 0)] = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  }
  return global_positions(motion);
}

// The halfway blend of frame f of `a` and frame g of `b` (same skeleton),
// root at the identity: local rotations slerped the short way, as a blend
// or an inertializer does, local positions lerped.
std::vector<glm::vec3> halfway_blend(const Motion& a, std::uint32_t f, const Motion& b, std::uint32_t g) {
  Motion blend;
  blend.skeleton = a.skeleton;
  blend.fps = a.fps;
  blend.frame_count = 1;
  for (std::size_t j = 0; j < a.joint_count(); ++j) {
    const glm::quat qa = a.local_rotations[a.index(f, j)];
    glm::quat qb = b.local_rotations[b.index(g, j)];
    if (glm::dot(qa, qb) < 0.0f) qb = -qb;
    blend.local_rotations.push_back(j == 0 ? glm::quat(1.0f, 0.0f, 0.0f, 0.0f) : glm::slerp(qa, qb, 0.5f));
    blend.local_positions.push_back(
        j == 0 ? glm::vec3(0.0f) : glm::mix(a.local_positions[a.index(f, j)], b.local_positions[b.index(g, j)], 0.5f));
  }
  return global_positions(blend);
}

float distance_to_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float span = glm::dot(ab, ab);
  const float t = span > 0.0f ? std::clamp(glm::dot(p - a, ab) / span, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

// A jump from a clip to the nearest posture of its mirror blends the two
// poses: halfway, every joint stays near the straight line between its two
// positions. It used to swing the upper body through a half turn on CMU
// skeletons (the spine's mirrored local rotations were turned by 180 degrees
// about the bone, undone by the next joint), taking the hands 0.45-0.55 m off.
TEST(ImportData, MirrorBlendStaysWithinItsTwoPoses) {
  MMVK_REQUIRE_DATA_DIR(dir);
  for (const char* path : {"cmu/cgspeed-16/16_23.bvh", "cmu/cgspeed-16/16_41.bvh", "cmu/amc2bvh-131/131_01.bvh",
                           "cmu/amc2bvh-131/131_09.bvh"}) {
    SCOPED_TRACE(path);
    const Motion motion = load_motion(dir / path);
    const auto mirrored = mmvk::mirror(motion);
    ASSERT_TRUE(mirrored.ok()) << mirrored.message();
    const std::vector<glm::vec3> original = root_relative_positions(motion);
    const std::vector<glm::vec3> reflected = root_relative_positions(*mirrored);
    const std::size_t joints = motion.joint_count();
    float worst = 0.0f;
    std::string worst_joint;
    int blends = 0;
    for (std::uint32_t f = 0; f < motion.frame_count; f += 3) {
      // The mirrored frame whose posture is nearest (summed joint distance).
      std::uint32_t nearest = 0;
      float nearest_distance = INFINITY;
      for (std::uint32_t g = 0; g < mirrored->frame_count; ++g) {
        float distance = 0.0f;
        for (std::size_t j = 0; j < joints; ++j) {
          distance += glm::length(original[f * joints + j] - reflected[g * joints + j]);
        }
        if (distance < nearest_distance) nearest_distance = distance, nearest = g;
      }
      // Only postures as near as a motion matching jump's (5 cm a joint on
      // average): far postures blend through arcs of their own.
      if (nearest_distance > 0.05f * float(joints)) continue;
      ++blends;
      const std::vector<glm::vec3> blend = halfway_blend(motion, f, *mirrored, nearest);
      for (std::size_t j = 0; j < joints; ++j) {
        const glm::vec3 a = original[f * joints + j];
        const glm::vec3 b = reflected[nearest * joints + j];
        // Off the line by at most a quarter of the two poses' distance, and
        // 2 cm: a blend of two rotations bends its path a little.
        const float excess = distance_to_segment(blend[j], a, b) - 0.25f * glm::length(b - a);
        if (excess > worst) worst = excess, worst_joint = motion.skeleton.names[j];
      }
    }
    EXPECT_GE(blends, 10) << "too few near postures to judge";
    EXPECT_LT(worst, 0.02f) << "metres, at " << worst_joint << " (" << blends << " blends)";
  }
}

TEST(ImportData, BandaiHipsAreNotTheStaticRoot) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Motion motion = load_motion(dir / kBandaiWalk);
  ASSERT_EQ(motion.skeleton.names[0], "joint_Root");
  EXPECT_EQ(motion.skeleton.names[static_cast<std::size_t>(bone(motion, "@hips"))], "Hips");
  // joint_Root is static at the origin; the body's translation is on Hips.
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    ASSERT_EQ(motion.local_positions[motion.index(f, 0)], glm::vec3(0.0f));
  }
  const auto root = mmvk::compute_character_root(motion, {});
  ASSERT_TRUE(root.ok()) << root.message();
  const auto positions = global_positions(motion);
  const std::size_t hips = static_cast<std::size_t>(bone(motion, "@hips"));
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    const glm::vec3 h = positions[f * motion.joint_count() + hips];
    EXPECT_EQ(root->positions[f], glm::vec3(h.x, 0.0f, h.z));
    EXPECT_NEAR(glm::length(root->facings[f]), 1.0f, 1e-5f);
    EXPECT_EQ(root->facings[f].y, 0.0f);
  }
}

TEST(ImportData, BandaiStraightWalkMovesForwardAtWalkingSpeed) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Motion motion = load_motion(dir / kBandaiWalk);
  const auto root = mmvk::compute_character_root(motion, {});
  ASSERT_TRUE(root.ok()) << root.message();
  // The middle half of the clip (the actor starts from rest).
  const std::uint32_t first = motion.frame_count / 4;
  const std::uint32_t last = 3 * motion.frame_count / 4;
  const glm::vec3 displacement = root->positions[last] - root->positions[first];
  const float seconds = static_cast<float>(last - first) / motion.fps;
  glm::vec3 facing(0.0f);
  for (std::uint32_t f = first; f <= last; ++f) facing += root->facings[f];
  facing = glm::normalize(facing);
  const float speed = glm::length(displacement) / seconds;
  const float forward_speed = glm::dot(displacement, facing) / seconds;
  EXPECT_GT(forward_speed, 1.1f) << "m/s";
  EXPECT_LT(forward_speed, 1.3f) << "m/s";
  EXPECT_GT(forward_speed, 0.98f * speed) << "the root must move along its facing";
  // And the facing barely turns on a straight walk.
  for (std::uint32_t f = first; f <= last; ++f) EXPECT_GT(glm::dot(root->facings[f], facing), 0.95f) << f;
}

TEST(ImportData, RolesResolveOnEverySkeleton) {
  MMVK_REQUIRE_DATA_DIR(dir);
  // Names from SOURCES.md's "Feature joints".
  struct Case {
    const char* path;
    const char* hips;
    const char* left_upper_leg;
    const char* right_foot;
    const char* left_toe;  // nullptr: the skeleton has none
  };
  const Case cases[] = {
      {"cmu/amc2bvh-131/131_01.bvh", "root", "lfemur", "rfoot", "ltoes"},
      {"cmu/cgspeed-max/131_01.bvh", "Hips", "LeftHip", "RightAnkle", "LeftToe"},
      {"cmu/cgspeed-mb/05_20.bvh", "Hips", "LeftUpLeg", "RightFoot", "LeftToeBase"},
      {"cmu/cgspeed-daz/05_20.bvh", "hip", "lThigh", "rFoot", nullptr},
      {kBandaiWalk, "Hips", "UpperLeg_L", "Foot_R", "Toes_L"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.path);
    const auto file = mmvk::load_bvh(dir / c.path);
    ASSERT_TRUE(file.ok()) << file.message();
    const auto motion = mmvk::motion_from_bvh(*file, {});
    ASSERT_TRUE(motion.ok()) << motion.message();
    const auto name = [&](const char* role) -> std::string {
      const auto index = mmvk::find_bone(motion->skeleton, role);
      return index.ok() ? motion->skeleton.names[static_cast<std::size_t>(*index)] : "(" + index.message() + ")";
    };
    EXPECT_EQ(name("@hips"), c.hips);
    EXPECT_EQ(name("@left_upper_leg"), c.left_upper_leg);
    EXPECT_EQ(name("@right_foot"), c.right_foot);
    if (c.left_toe) {
      EXPECT_EQ(name("@left_toe"), c.left_toe);
    } else {
      EXPECT_FALSE(mmvk::find_bone(motion->skeleton, "@left_toe").ok());
    }
    EXPECT_TRUE(mmvk::compute_character_root(*motion, {}).ok());
  }
}

TEST(ImportData, ResamplingKeepsCoincidentFramesAndDuration) {
  MMVK_REQUIRE_DATA_DIR(dir);
  const Motion motion = load_motion(dir / "cmu/amc2bvh-131/131_01.bvh");
  ASSERT_EQ(motion.fps, 120.0f);
  const auto at30 = mmvk::resample(motion, 30.0f);
  ASSERT_TRUE(at30.ok()) << at30.message();
  EXPECT_EQ(at30->frame_count, 249u);  // 993 / 4 intervals + 1
  for (std::uint32_t f = 0; f < at30->frame_count; ++f) {
    for (std::size_t j = 0; j < motion.joint_count(); ++j) {
      ASSERT_EQ(at30->local_positions[at30->index(f, j)], motion.local_positions[motion.index(4 * f, j)]);
      ASSERT_EQ(at30->local_rotations[at30->index(f, j)], motion.local_rotations[motion.index(4 * f, j)]);
    }
  }
  const Motion bandai = load_motion(dir / kBandaiWalk);
  const auto at60 = mmvk::resample(bandai, 60.0f);
  ASSERT_TRUE(at60.ok()) << at60.message();
  EXPECT_EQ(at60->frame_count, 2 * bandai.frame_count - 1);
  EXPECT_FLOAT_EQ((at60->frame_count - 1) / at60->fps, (bandai.frame_count - 1) / bandai.fps);
}

TEST(ImportData, DebianAssimpSampleLoads) {
  // The default data for users (assimp-testmodels). CI installs it.
  const fs::path path = "/usr/share/assimp/models/BVH/01_01.bvh";
  if (!fs::exists(path)) {
    const char* required = std::getenv("MMVK_REQUIRE_DATA");
    if (required && std::string(required) == "1") FAIL() << path << " missing (apt-get install assimp-testmodels)";
    GTEST_SKIP() << path << " not installed";
  }
  const Motion motion = load_motion(path);
  EXPECT_EQ(motion.frame_count, 2752u);
  EXPECT_EQ(motion.fps, 120.0f);
  EXPECT_TRUE(mmvk::compute_character_root(motion, {}).ok());
}

}  // namespace
