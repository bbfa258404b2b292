// motion_from_bvh, forward kinematics, resampling, mirroring, bone roles and
// the character root, on small generated skeletons and motions.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/import/motion.hpp"

namespace {

using mmvk::Motion;
using mmvk::Skeleton;

constexpr float kPi = glm::pi<float>();

mmvk::BvhFile parse(const std::string& text) {
  auto file = mmvk::parse_bvh(text, "gen.bvh");
  EXPECT_TRUE(file.ok()) << file.message();
  return file.ok() ? std::move(file).value() : mmvk::BvhFile{};
}

Motion import(const std::string& text, const mmvk::ImportOptions& options) {
  auto motion = mmvk::motion_from_bvh(parse(text), options);
  EXPECT_TRUE(motion.ok()) << motion.message();
  return motion.ok() ? std::move(motion).value() : Motion{};
}

// One root with the given channels and one frame of values.
std::string one_joint_bvh(const std::string& channels, int count, const std::string& values,
                          const std::string& offset = "0 0 0", const std::string& frame_time = "0.0333333") {
  return "HIERARCHY\nROOT R\n{\n OFFSET " + offset + "\n CHANNELS " + std::to_string(count) + " " + channels +
         "\n JOINT C\n {\n  OFFSET 0 1 0\n  CHANNELS 0\n }\n}\nMOTION\nFrames: 1\nFrame Time: " + frame_time + "\n" +
         values + "\n";
}

glm::vec3 rotate(const glm::mat4& m, glm::vec3 v) { return glm::vec3(m * glm::vec4(v, 0.0f)); }

void expect_near(glm::vec3 a, glm::vec3 b, float tolerance, const std::string& what = "") {
  EXPECT_NEAR(a.x, b.x, tolerance) << what;
  EXPECT_NEAR(a.y, b.y, tolerance) << what;
  EXPECT_NEAR(a.z, b.z, tolerance) << what;
}

// --- Import -----------------------------------------------------------------

TEST(MotionFromBvh, RotationChannelsComposeIntrinsicallyInFileOrder) {
  const mmvk::ImportOptions options{.metres_per_unit = 1.0f};
  const Motion zxy = import(one_joint_bvh("Zrotation Xrotation Yrotation", 3, "30 40 50"), options);
  const Motion xyz = import(one_joint_bvh("Xrotation Yrotation Zrotation", 3, "40 50 30"), options);
  // Reference: matrices multiplied left to right in channel order.
  const glm::mat4 rz = glm::rotate(glm::mat4(1.0f), glm::radians(30.0f), glm::vec3(0, 0, 1));
  const glm::mat4 rx = glm::rotate(glm::mat4(1.0f), glm::radians(40.0f), glm::vec3(1, 0, 0));
  const glm::mat4 ry = glm::rotate(glm::mat4(1.0f), glm::radians(50.0f), glm::vec3(0, 1, 0));
  for (const glm::vec3 v : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0.3f, -0.2f, 0.9f)}) {
    expect_near(zxy.local_rotations[0] * v, rotate(rz * rx * ry, v), 1e-5f, "ZXY");
    expect_near(xyz.local_rotations[0] * v, rotate(rx * ry * rz, v), 1e-5f, "XYZ");
  }
}

TEST(MotionFromBvh, PositionChannelsReplaceTheOffset) {
  const mmvk::ImportOptions options{.metres_per_unit = 0.01f};
  const Motion full = import(one_joint_bvh("Xposition Yposition Zposition", 3, "4 5 6", "100 200 300"), options);
  expect_near(full.local_positions[0], glm::vec3(0.04f, 0.05f, 0.06f), 1e-7f);
  // Only Y animated: X and Z keep the OFFSET.
  const Motion partial = import(one_joint_bvh("Yposition", 1, "5", "100 200 300"), options);
  expect_near(partial.local_positions[0], glm::vec3(1.0f, 0.05f, 3.0f), 1e-6f);
  // No position channel: the OFFSET, scaled; rest offsets are scaled too.
  expect_near(partial.local_positions[1], glm::vec3(0.0f, 0.01f, 0.0f), 1e-7f);
  expect_near(partial.skeleton.rest_offsets[0], glm::vec3(1.0f, 2.0f, 3.0f), 1e-6f);
  EXPECT_EQ(partial.skeleton.names, (std::vector<std::string>{"R", "C"}));
  EXPECT_EQ(partial.skeleton.parents, (std::vector<int>{-1, 0}));
}

TEST(MotionFromBvh, FpsIsSnappedToWholeRates) {
  const mmvk::ImportOptions options{.metres_per_unit = 1.0f};
  EXPECT_EQ(import(one_joint_bvh("Xrotation", 1, "0", "0 0 0", ".0083333"), options).fps, 120.0f);
  EXPECT_EQ(import(one_joint_bvh("Xrotation", 1, "0", "0 0 0", "0.0333333"), options).fps, 30.0f);
  EXPECT_EQ(import(one_joint_bvh("Xrotation", 1, "0", "0 0 0", "0.016666666666666666"), options).fps, 60.0f);
  EXPECT_NEAR(import(one_joint_bvh("Xrotation", 1, "0", "0 0 0", "0.011"), options).fps, 90.909f, 1e-3f);
}

TEST(MotionFromBvh, ZUpFilesAreTurnedToYUp) {
  const mmvk::ImportOptions options{.metres_per_unit = 1.0f, .up_axis = mmvk::UpAxis::Z};
  // The child sits 1 unit "up" (+Z in the file); the root is at (1, 2, 3).
  std::string text = one_joint_bvh("Xposition Yposition Zposition", 3, "1 2 3");
  text.replace(text.find("OFFSET 0 1 0"), 12, "OFFSET 0 0 1");
  const Motion motion = import(text, options);
  std::vector<glm::vec3> positions(2);
  std::vector<glm::quat> rotations(2);
  mmvk::forward_kinematics(motion, 0, positions, rotations);
  expect_near(positions[0], glm::vec3(1.0f, 3.0f, -2.0f), 1e-6f);
  expect_near(positions[1] - positions[0], glm::vec3(0.0f, 1.0f, 0.0f), 1e-6f);
}

TEST(MotionFromBvh, GuessesUnitsFromTheSkeletonSize) {
  // A stick figure: legs and arms from a pelvis, total span `span` units.
  const auto figure = [](float span) {
    const float leg = 0.45f * span;
    const float arm = 0.55f * span;
    const auto f = [](float v) { return std::to_string(v); };
    return "HIERARCHY\nROOT Hips\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n"
           " JOINT Leg\n {\n  OFFSET 0 -" + f(leg) + " 0\n  CHANNELS 0\n }\n"
           " JOINT Arm\n {\n  OFFSET 0 " + f(arm) + " 0\n  CHANNELS 0\n  End Site\n  {\n   OFFSET 0 0 0\n  }\n }\n}\n"
           "MOTION\nFrames: 0\nFrame Time: 0.01\n";
  };
  EXPECT_EQ(mmvk::guess_metres_per_unit(parse(figure(190.0f))), 0.01f);     // cm
  EXPECT_EQ(mmvk::guess_metres_per_unit(parse(figure(85.0f))), 0.0254f);    // inches
  EXPECT_EQ(mmvk::guess_metres_per_unit(parse(figure(39.0f))), 0.05644f);   // CMU ASF units
  EXPECT_EQ(mmvk::guess_metres_per_unit(parse(figure(2.1f))), 1.0f);        // metres
  // The guess is used when metres_per_unit is 0.
  const Motion motion = import(figure(39.0f), {});
  EXPECT_NEAR(motion.skeleton.rest_offsets[1].y, -0.45f * 39.0f * 0.05644f, 1e-5f);
}

TEST(MotionFromBvh, RejectsInconsistentFilesAndOptions) {
  mmvk::BvhFile file = parse(one_joint_bvh("Xrotation", 1, "0"));
  file.values.push_back(1.0f);
  const auto bad = mmvk::motion_from_bvh(file, {});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("gen.bvh"), std::string::npos) << bad.message();
  file.values.pop_back();
  const auto negative = mmvk::motion_from_bvh(file, {.metres_per_unit = -1.0f});
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.message().find("metres_per_unit"), std::string::npos) << negative.message();
  file.frame_time = 0.0;
  EXPECT_FALSE(mmvk::motion_from_bvh(file, {}).ok());
}

// --- Forward kinematics -----------------------------------------------------

// A chain root -> a -> b, unit offsets along +X, with the given local
// rotations; one frame.
Motion chain(const std::vector<glm::quat>& rotations, glm::vec3 root_position) {
  Motion motion;
  motion.skeleton.names = {"root", "a", "b"};
  motion.skeleton.parents = {-1, 0, 1};
  motion.skeleton.rest_offsets = {glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(1, 0, 0)};
  motion.fps = 30.0f;
  motion.frame_count = 1;
  motion.local_positions = {root_position, glm::vec3(1, 0, 0), glm::vec3(1, 0, 0)};
  motion.local_rotations = rotations;
  return motion;
}

TEST(ForwardKinematics, ComposesParentTransforms) {
  const glm::quat yaw90 = glm::angleAxis(kPi / 2, glm::vec3(0, 1, 0));
  const glm::quat none(1, 0, 0, 0);
  const Motion motion = chain({yaw90, yaw90, none}, glm::vec3(5, 1, 0));
  std::vector<glm::vec3> positions(3);
  std::vector<glm::quat> rotations(3);
  mmvk::forward_kinematics(motion, 0, positions, rotations);
  // Root yawed 90 degrees: its +X points to -Z. `a` adds another 90: -X.
  expect_near(positions[0], glm::vec3(5, 1, 0), 1e-6f);
  expect_near(positions[1], glm::vec3(5, 1, -1), 1e-6f);
  expect_near(positions[2], glm::vec3(4, 1, -1), 1e-6f);
  expect_near(rotations[2] * glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), 1e-6f);

  std::vector<glm::vec3> all(3);
  std::vector<glm::quat> all_rotations(3);
  mmvk::forward_kinematics_clip(motion, all, all_rotations);
  EXPECT_EQ(all, positions);
}

// --- Resampling ---------------------------------------------------------------

// A root moving along +X at 1 unit/s and yawing at 90 degrees/s, `frames`
// frames at `fps`.
Motion moving(std::uint32_t frames, float fps) {
  Motion motion;
  motion.skeleton.names = {"root"};
  motion.skeleton.parents = {-1};
  motion.skeleton.rest_offsets = {glm::vec3(0.0f)};
  motion.fps = fps;
  motion.frame_count = frames;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const float t = static_cast<float>(f) / fps;
    motion.local_positions.push_back(glm::vec3(t, 1.0f, 0.0f));
    motion.local_rotations.push_back(glm::angleAxis(t * kPi / 2, glm::vec3(0, 1, 0)));
  }
  return motion;
}

TEST(Resample, KeepsTheDurationAndInterpolates) {
  const Motion source = moving(121, 120.0f);  // exactly 1 s
  const auto down = mmvk::resample(source, 30.0f);
  ASSERT_TRUE(down.ok()) << down.message();
  EXPECT_EQ(down->fps, 30.0f);
  EXPECT_EQ(down->frame_count, 31u);
  EXPECT_EQ(down->local_positions.back(), source.local_positions.back());

  const auto up = mmvk::resample(moving(31, 30.0f), 60.0f);
  ASSERT_TRUE(up.ok()) << up.message();
  EXPECT_EQ(up->frame_count, 61u);
  for (std::uint32_t f = 0; f < up->frame_count; ++f) {
    const float t = static_cast<float>(f) / 60.0f;
    expect_near(up->local_positions[f], glm::vec3(t, 1.0f, 0.0f), 1e-5f);
    // Slerp between keys of a constant-rate yaw gives the exact in-between yaw.
    const glm::quat expected = glm::angleAxis(t * kPi / 2, glm::vec3(0, 1, 0));
    EXPECT_NEAR(std::abs(glm::dot(up->local_rotations[f], expected)), 1.0f, 1e-5f) << f;
  }
  // A rate that does not divide: 30 -> 45 fps over 1 s.
  const auto odd = mmvk::resample(moving(31, 30.0f), 45.0f);
  ASSERT_TRUE(odd.ok());
  EXPECT_EQ(odd->frame_count, 46u);
  expect_near(odd->local_positions[1], glm::vec3(1.0f / 45.0f, 1.0f, 0.0f), 1e-5f);
}

TEST(Resample, TakesTheShortArcForNegatedQuaternions) {
  Motion motion = moving(2, 30.0f);
  motion.local_rotations[0] = glm::angleAxis(0.0f, glm::vec3(0, 1, 0));
  motion.local_rotations[1] = -glm::angleAxis(0.2f, glm::vec3(0, 1, 0));  // same rotation as +0.2 rad
  const auto up = mmvk::resample(motion, 60.0f);
  ASSERT_TRUE(up.ok());
  ASSERT_EQ(up->frame_count, 3u);
  EXPECT_NEAR(std::abs(glm::dot(up->local_rotations[1], glm::angleAxis(0.1f, glm::vec3(0, 1, 0)))), 1.0f, 1e-6f);
}

TEST(Resample, HandlesShortClipsAndRejectsBadRates) {
  EXPECT_EQ(mmvk::resample(moving(0, 120.0f), 30.0f)->frame_count, 0u);
  EXPECT_EQ(mmvk::resample(moving(1, 120.0f), 30.0f)->frame_count, 1u);
  for (const float fps : {0.0f, -30.0f, std::nanf(""), INFINITY}) {
    const auto bad = mmvk::resample(moving(10, 120.0f), fps);
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.message().find("fps"), std::string::npos) << bad.message();
  }
}

// --- Mirroring ------------------------------------------------------------------

Skeleton skeleton_named(const std::vector<std::string>& names) {
  Skeleton skeleton;
  skeleton.names = names;
  skeleton.parents.assign(names.size(), 0);
  skeleton.parents[0] = -1;
  skeleton.rest_offsets.assign(names.size(), glm::vec3(0.0f));
  return skeleton;
}

std::vector<std::string> partner_names(const Skeleton& skeleton) {
  const std::vector<int> pairs = mmvk::mirror_pairs(skeleton);
  std::vector<std::string> out;
  for (const int p : pairs) out.push_back(skeleton.names[static_cast<std::size_t>(p)]);
  return out;
}

TEST(Mirror, PairsJointsByTheNamingConventionsInTheData) {
  EXPECT_EQ(partner_names(skeleton_named({"Hips", "LeftUpLeg", "RightUpLeg", "Spine"})),
            (std::vector<std::string>{"Hips", "RightUpLeg", "LeftUpLeg", "Spine"}));
  EXPECT_EQ(partner_names(skeleton_named({"root", "lfemur", "rfemur", "lowerback", "lowerneck"})),
            (std::vector<std::string>{"root", "rfemur", "lfemur", "lowerback", "lowerneck"}));
  EXPECT_EQ(partner_names(skeleton_named({"Hips", "LHipJoint", "RHipJoint", "LThumb", "RThumb"})),
            (std::vector<std::string>{"Hips", "RHipJoint", "LHipJoint", "RThumb", "LThumb"}));
  EXPECT_EQ(partner_names(skeleton_named({"hip", "lThigh", "rThigh", "lCollar", "rCollar", "leftEye", "rightEye"})),
            (std::vector<std::string>{"hip", "rThigh", "lThigh", "rCollar", "lCollar", "rightEye", "leftEye"}));
  EXPECT_EQ(partner_names(skeleton_named({"joint_Root", "Foot_L", "Foot_R", "hand.l", "hand.r"})),
            (std::vector<std::string>{"joint_Root", "Foot_R", "Foot_L", "hand.r", "hand.l"}));
  // No partner: stays itself.
  EXPECT_EQ(partner_names(skeleton_named({"Hips", "LeftArm", "Lamp"})),
            (std::vector<std::string>{"Hips", "LeftArm", "Lamp"}));
}

// A Bandai-like skeleton whose local frames are not world aligned: the hips
// reflect across local Y, the limbs across local X. Random local rotations.
Motion random_bandai_like(std::uint32_t frames, unsigned seed) {
  Motion motion;
  Skeleton& s = motion.skeleton;
  s.names = {"joint_Root", "Hips", "UpperLeg_L", "LowerLeg_L", "Foot_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Spine"};
  s.parents = {-1, 0, 1, 2, 3, 1, 5, 6, 1};
  s.rest_offsets = {glm::vec3(0.0f),         glm::vec3(0.0f, 0.93f, 0.0f), glm::vec3(-0.02f, -0.065f, 0.0f),
                    glm::vec3(0.39f, 0, 0), glm::vec3(0.41f, 0, 0.01f),  glm::vec3(-0.02f, 0.065f, 0.0f),
                    glm::vec3(-0.39f, 0, 0), glm::vec3(-0.41f, 0, 0.01f), glm::vec3(0.157f, 0, 0)};
  motion.fps = 30.0f;
  motion.frame_count = frames;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (std::size_t j = 0; j < s.size(); ++j) {
      glm::vec3 position = s.rest_offsets[j];
      if (j == 1) position = glm::vec3(unit(rng), 0.9f + 0.05f * unit(rng), unit(rng));
      motion.local_positions.push_back(position);
      motion.local_rotations.push_back(
          glm::normalize(glm::quat(unit(rng) + 1.5f, unit(rng), unit(rng), unit(rng))));
    }
  }
  return motion;
}

TEST(Mirror, TwiceIsTheIdentityExactly) {
  const Motion motion = random_bandai_like(50, 7);
  const auto once = mmvk::mirror(motion);
  ASSERT_TRUE(once.ok()) << once.message();
  const auto twice = mmvk::mirror(*once);
  ASSERT_TRUE(twice.ok()) << twice.message();
  EXPECT_EQ(twice->local_positions, motion.local_positions);
  EXPECT_EQ(twice->local_rotations, motion.local_rotations);
  EXPECT_EQ(twice->skeleton.names, motion.skeleton.names);
  EXPECT_NE(once->local_positions, motion.local_positions);
}

TEST(Mirror, ReflectsModelSpacePositionsOntoPartners) {
  const Motion motion = random_bandai_like(20, 11);
  const auto mirrored = mmvk::mirror(motion);
  ASSERT_TRUE(mirrored.ok()) << mirrored.message();
  const std::vector<int> pairs = mmvk::mirror_pairs(motion.skeleton);
  const std::size_t n = motion.joint_count();
  std::vector<glm::vec3> p(n), m(n);
  std::vector<glm::quat> q(n), r(n);
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    mmvk::forward_kinematics(motion, f, p, q);
    mmvk::forward_kinematics(*mirrored, f, m, r);
    for (std::size_t j = 0; j < n; ++j) {
      const glm::vec3 source = p[static_cast<std::size_t>(pairs[j])];
      expect_near(m[j], glm::vec3(-source.x, source.y, source.z), 1e-5f, motion.skeleton.names[j]);
    }
  }
}

TEST(Mirror, RejectsPartnersWithUnpairedParents) {
  Motion motion = random_bandai_like(2, 3);
  motion.skeleton.parents[5] = 8;  // UpperLeg_R under Spine, UpperLeg_L under Hips
  const auto mirrored = mmvk::mirror(motion);
  ASSERT_FALSE(mirrored.ok());
  EXPECT_NE(mirrored.message().find("UpperLeg_L"), std::string::npos) << mirrored.message();
}

// --- Bone roles -------------------------------------------------------------------

TEST(BoneRoles, ResolveNamesAndRoles) {
  Skeleton bandai = random_bandai_like(1, 1).skeleton;
  EXPECT_EQ(*mmvk::find_bone(bandai, "@hips"), 1);  // Hips, not joint_Root
  EXPECT_EQ(*mmvk::find_bone(bandai, "@left_upper_leg"), 2);
  EXPECT_EQ(*mmvk::find_bone(bandai, "@right_lower_leg"), 6);
  EXPECT_EQ(*mmvk::find_bone(bandai, "@left_foot"), 4);
  EXPECT_EQ(*mmvk::find_bone(bandai, "Spine"), 8);

  // The hips are where the legs meet, whatever they are called.
  Skeleton odd = skeleton_named({"scene", "body", "LeftUpLeg", "RightUpLeg"});
  odd.parents = {-1, 0, 1, 1};
  EXPECT_EQ(*mmvk::find_bone(odd, "@hips"), 1);

  const auto missing = mmvk::find_bone(bandai, "@left_toe");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("@left_toe"), std::string::npos);
  EXPECT_NE(missing.message().find("UpperLeg_L"), std::string::npos) << "lists the joints: " << missing.message();
  const auto unknown = mmvk::find_bone(bandai, "@tail");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("@left_foot"), std::string::npos) << "lists the roles: " << unknown.message();
  const auto no_joint = mmvk::find_bone(bandai, "Tail");
  ASSERT_FALSE(no_joint.ok());
  EXPECT_NE(no_joint.message().find("Tail"), std::string::npos);
  EXPECT_FALSE(mmvk::find_bone(bandai, "").ok());
}

TEST(BoneRoles, KnowEachSourceConvention) {
  struct Case {
    std::vector<std::string> names;
    const char* role;
    const char* expected;
  };
  const Case cases[] = {
      {{"root", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes"}, "@left_toe", "ltoes"},
      {{"root", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes"}, "@left_upper_leg", "lfemur"},
      {{"Hips", "RHipJoint", "RightHip", "RightKnee", "RightAnkle", "RightToe"}, "@right_upper_leg", "RightHip"},
      {{"Hips", "RHipJoint", "RightHip", "RightKnee", "RightAnkle", "RightToe"}, "@right_foot", "RightAnkle"},
      {{"Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase"}, "@left_lower_leg", "LeftLeg"},
      {{"Hips", "LHipJoint", "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase"}, "@left_toe", "LeftToeBase"},
      {{"hip", "rButtock", "rThigh", "rShin", "rFoot"}, "@right_lower_leg", "rShin"},
      {{"hip", "rButtock", "rThigh", "rShin", "rFoot"}, "@right_upper_leg", "rThigh"},
      {{"joint_Root", "Hips", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"}, "@right_toe", "Toes_R"},
      // Namespaced and prefixed exports.
      {{"mixamorig:Hips", "mixamorig:LeftUpLeg", "mixamorig:LeftLeg", "mixamorig:LeftFoot"}, "@left_foot",
       "mixamorig:LeftFoot"},
      {{"Bip01 Pelvis", "Bip01 L Thigh", "Bip01 L Calf", "Bip01 L Foot"}, "@left_upper_leg", "Bip01 L Thigh"},
  };
  for (const Case& c : cases) {
    Skeleton skeleton = skeleton_named(c.names);
    for (std::size_t j = 1; j < c.names.size(); ++j) skeleton.parents[j] = static_cast<int>(j) - 1;
    const auto index = mmvk::find_bone(skeleton, c.role);
    ASSERT_TRUE(index.ok()) << index.message();
    EXPECT_EQ(skeleton.names[static_cast<std::size_t>(*index)], c.expected) << c.role;
  }
}

// --- Character root -----------------------------------------------------------------

// Hips walking at 1 m/s along a heading `yaw` (radians about +Y), the hips'
// local +Z facing the heading, left hip at local +X. Optional yaw wobble.
Motion walker(float yaw, std::uint32_t frames, float wobble_degrees) {
  Motion motion;
  motion.skeleton = skeleton_named({"Hips", "LeftUpLeg", "RightUpLeg"});
  motion.skeleton.rest_offsets = {glm::vec3(0.0f), glm::vec3(0.1f, 0, 0), glm::vec3(-0.1f, 0, 0)};
  motion.fps = 30.0f;
  motion.frame_count = frames;
  const glm::vec3 heading(std::sin(yaw), 0.0f, std::cos(yaw));
  for (std::uint32_t f = 0; f < frames; ++f) {
    const float t = static_cast<float>(f) / motion.fps;
    const float wobble = glm::radians(wobble_degrees) * std::sin(2.0f * kPi * 2.0f * t);  // 2 Hz
    motion.local_positions.push_back(heading * t + glm::vec3(0.0f, 0.9f, 0.0f));
    motion.local_positions.push_back(motion.skeleton.rest_offsets[1]);
    motion.local_positions.push_back(motion.skeleton.rest_offsets[2]);
    motion.local_rotations.push_back(glm::angleAxis(yaw + wobble, glm::vec3(0, 1, 0)));
    motion.local_rotations.push_back(glm::quat(1, 0, 0, 0));
    motion.local_rotations.push_back(glm::quat(1, 0, 0, 0));
  }
  return motion;
}

TEST(CharacterRoot, ProjectsTheHipsAndFacesForward) {
  for (const float yaw : {0.0f, 0.7f, -2.5f}) {
    const Motion motion = walker(yaw, 60, 0.0f);
    const auto root = mmvk::compute_character_root(motion, {});
    ASSERT_TRUE(root.ok()) << root.message();
    ASSERT_EQ(root->positions.size(), 60u);
    for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
      const glm::vec3 hips = motion.local_positions[motion.index(f, 0)];
      EXPECT_EQ(root->positions[f], glm::vec3(hips.x, 0.0f, hips.z));
      expect_near(root->facings[f], glm::vec3(std::sin(yaw), 0.0f, std::cos(yaw)), 1e-5f);
    }
  }
}

TEST(CharacterRoot, SmoothsTheFacing) {
  const Motion motion = walker(0.0f, 90, 20.0f);
  const auto raw = mmvk::compute_character_root(motion, {.facing_smoothing_seconds = 0.0f});
  const auto smooth = mmvk::compute_character_root(motion, {.facing_smoothing_seconds = 0.5f});
  ASSERT_TRUE(raw.ok() && smooth.ok());
  float raw_spread = 0.0f;
  float smooth_spread = 0.0f;
  for (std::uint32_t f = 15; f < 75; ++f) {  // away from the window's cut at the ends
    raw_spread = std::max(raw_spread, std::abs(raw->facings[f].x));
    smooth_spread = std::max(smooth_spread, std::abs(smooth->facings[f].x));
    EXPECT_NEAR(glm::length(smooth->facings[f]), 1.0f, 1e-5f);
  }
  EXPECT_NEAR(raw_spread, std::sin(glm::radians(20.0f)), 0.01f);
  EXPECT_LT(smooth_spread, 0.3f * raw_spread);
}

TEST(CharacterRoot, SourceBoneIsConfigurableAndErrorsAreNamed) {
  const Motion motion = walker(0.0f, 10, 0.0f);
  const auto from_leg = mmvk::compute_character_root(motion, {.source_bone = "LeftUpLeg"});
  ASSERT_TRUE(from_leg.ok()) << from_leg.message();
  EXPECT_NEAR(from_leg->positions[0].x, 0.1f, 1e-6f);

  const auto unknown = mmvk::compute_character_root(motion, {.source_bone = "Pelvis"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("Pelvis"), std::string::npos) << unknown.message();
  const auto negative = mmvk::compute_character_root(motion, {.facing_smoothing_seconds = -1.0f});
  ASSERT_FALSE(negative.ok());
  EXPECT_NE(negative.message().find("facing_smoothing_seconds"), std::string::npos);

  Motion legless = motion;
  legless.skeleton.names[1] = "Arm";
  const auto no_legs = mmvk::compute_character_root(legless, {});
  ASSERT_FALSE(no_legs.ok());
  EXPECT_NE(no_legs.message().find("upper leg"), std::string::npos) << no_legs.message();
}

}  // namespace
