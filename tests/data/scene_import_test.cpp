// FBX, glTF and COLLADA through assimp (mmvk/import/scene_import.hpp), on
// assimp-testmodels' animated skeletons and on glTF files this test writes
// from the project's BVH clips.
//
// - The imported motion's forward kinematics, and the built database's,
//   agree with the scene's own node transforms, evaluated here from assimp's
//   keys with glm (lerp, slerp) and its node matrices, at sampled times.
// - A glTF written from a CMU clip (its joints as nodes, the root's
//   translation and every joint's rotation as 120 fps keys) gives the same
//   features as the BVH within 1e-3 (normalized units; float32 keys).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#define GLM_ENABLE_EXPERIMENTAL
#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/euler_angles.hpp>
#include <glm/mat4x4.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/import/motion.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/import/scene_import.hpp"
#include "support/command.hpp"
#include "support/test_data.hpp"

namespace {

namespace fs = std::filesystem;
using mmvk::Motion;

const fs::path kModels = "/usr/share/assimp/models";

// The file, or a failure under MMVK_REQUIRE_DATA=1 (CI installs
// assimp-testmodels), else a skip.
#define MMVK_REQUIRE_TEST_MODEL(path)                                                            \
  if (!fs::exists(path)) {                                                                       \
    const char* required = std::getenv("MMVK_REQUIRE_DATA");                                     \
    if (required && std::string(required) == "1") FAIL() << path << " missing (apt-get install assimp-testmodels)"; \
    GTEST_SKIP() << path << " not installed";                                                    \
  }

// The scene's world node matrices at `seconds`, evaluated independently of
// the importer: keys interpolated with glm, node matrices multiplied down.
std::map<std::string, aiMatrix4x4> assimp_world_matrices(const aiScene& scene, const aiAnimation& animation,
                                                         double seconds) {
  const double ticks = (animation.mTicksPerSecond > 0.0 ? animation.mTicksPerSecond : 25.0) *
                       std::min(seconds, animation.mDuration / (animation.mTicksPerSecond > 0.0 ? animation.mTicksPerSecond : 25.0));
  std::map<std::string, const aiNodeAnim*> channels;
  for (unsigned c = 0; c < animation.mNumChannels; ++c) channels[animation.mChannels[c]->mNodeName.C_Str()] = animation.mChannels[c];
  auto at = [&](const auto* keys, unsigned count, auto convert, auto blend) {
    unsigned k = 0;
    while (k + 1 < count && keys[k + 1].mTime <= ticks) ++k;
    if (k + 1 >= count || ticks <= keys[0].mTime) return convert(keys[ticks <= keys[0].mTime ? 0 : k].mValue);
    const float t = float((ticks - keys[k].mTime) / (keys[k + 1].mTime - keys[k].mTime));
    return blend(convert(keys[k].mValue), convert(keys[k + 1].mValue), t);
  };
  auto vec = [](const aiVector3D& v) { return glm::vec3(v.x, v.y, v.z); };
  auto quat = [](const aiQuaternion& q) { return glm::quat(q.w, q.x, q.y, q.z); };
  auto mix = [](glm::vec3 a, glm::vec3 b, float t) { return a + (b - a) * t; };
  auto slerp = [](glm::quat a, glm::quat b, float t) { return glm::slerp(a, glm::dot(a, b) < 0 ? -b : b, t); };
  std::map<std::string, aiMatrix4x4> out;
  std::vector<std::pair<const aiNode*, aiMatrix4x4>> stack{{scene.mRootNode, aiMatrix4x4()}};
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    aiMatrix4x4 local = node->mTransformation;
    if (auto it = channels.find(node->mName.C_Str()); it != channels.end()) {
      const aiNodeAnim& ch = *it->second;
      const glm::vec3 p = at(ch.mPositionKeys, ch.mNumPositionKeys, vec, mix);
      const glm::quat r = glm::normalize(at(ch.mRotationKeys, ch.mNumRotationKeys, quat, slerp));
      const glm::vec3 s = at(ch.mScalingKeys, ch.mNumScalingKeys, vec, mix);
      local = aiMatrix4x4(aiVector3D(s.x, s.y, s.z), aiQuaternion(r.w, r.x, r.y, r.z), aiVector3D(p.x, p.y, p.z));
    }
    const aiMatrix4x4 global = parent * local;
    out.emplace(node->mName.C_Str(), global);
    for (unsigned c = 0; c < node->mNumChildren; ++c) stack.push_back({node->mChildren[c], global});
  }
  return out;
}

std::map<std::string, glm::vec3> assimp_world_positions(const aiScene& scene, const aiAnimation& animation,
                                                        double seconds) {
  std::map<std::string, glm::vec3> out;
  for (const auto& [name, m] : assimp_world_matrices(scene, animation, seconds)) out[name] = glm::vec3(m.a4, m.b4, m.c4);
  return out;
}

// A node frame's axis `column` (0 = x, 1 = y), normalized: scale dropped.
glm::vec3 axis_of(const aiMatrix4x4& m, int column) {
  const glm::vec3 axis = column == 0 ? glm::vec3(m.a1, m.b1, m.c1) : glm::vec3(m.a2, m.b2, m.c2);
  return glm::normalize(axis);
}

struct ModelCase {
  const char* file;
  std::size_t joints;  // the skeleton the import must find
};

// Every animated skeleton of assimp-testmodels that assimp 5.2.5 reads.
const ModelCase kModelCases[] = {
    {"FBX/animation_with_skeleton.fbx", 15},  // Armature + the skin's 14 bones
    {"FBX/huesitos.fbx", 10},
    {"glTF2/simple_skin/simple_skin.gltf", 2},  // the skin's two joints
    {"Collada/box_nested_animation.dae", 2},    // Armature + its bone
    {"Collada/anims_with_full_rotations_between_keys.DAE", 64},  // 64 animated boxes under one node
};

TEST(SceneImport, ForwardKinematicsAgreesWithAssimp) {
  for (const ModelCase& model : kModelCases) {
    SCOPED_TRACE(model.file);
    const fs::path path = kModels / model.file;
    MMVK_REQUIRE_TEST_MODEL(path);
    mmvk::SceneImportOptions options;
    options.fps = 30.0f;
    const auto imported = mmvk::import_scene(path, options);
    ASSERT_TRUE(imported.ok()) << imported.message();
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(path.string(), 0);
    ASSERT_NE(scene, nullptr);
    ASSERT_EQ(imported->animations.size(), scene->mNumAnimations);
    const Motion& motion = imported->animations[0].motion;
    ASSERT_EQ(motion.joint_count(), model.joints);
    std::vector<glm::vec3> positions(motion.joint_count());
    std::vector<glm::quat> rotations(motion.joint_count());
    float extent = 0.0f;  // the tolerance scales with the skeleton's size
    for (const glm::vec3& offset : motion.skeleton.rest_offsets) extent = std::max(extent, glm::length(offset));
    const std::uint32_t last = motion.frame_count - 1;
    for (const std::uint32_t frame : {0u, last / 3, last / 2, last}) {
      mmvk::forward_kinematics(motion, frame, positions, rotations);
      const auto expected = assimp_world_matrices(*scene, *scene->mAnimations[0], frame / 30.0);
      for (std::size_t j = 0; j < motion.joint_count(); ++j) {
        const aiMatrix4x4& m = expected.at(motion.skeleton.names[j]);
        const glm::vec3 want = glm::vec3(m.a4, m.b4, m.c4) * imported->metres_per_unit;
        EXPECT_LT(glm::length(positions[j] - want), 1e-4f * std::max(extent, 1.0f))
            << "frame " << frame << " joint " << motion.skeleton.names[j];
        // The joint's frame too (these files are Y-up: no axis change), not
        // only where it is: poses blend and IK turns rotations.
        EXPECT_GT(glm::dot(rotations[j] * glm::vec3(1, 0, 0), axis_of(m, 0)), 0.9999f)
            << "frame " << frame << " joint " << motion.skeleton.names[j];
        EXPECT_GT(glm::dot(rotations[j] * glm::vec3(0, 1, 0), axis_of(m, 1)), 0.9999f)
            << "frame " << frame << " joint " << motion.skeleton.names[j];
      }
    }
  }
}

// --- A glTF written from a BVH clip --------------------------------------

void append_floats(std::string& bin, std::span<const float> values) {
  bin.append(reinterpret_cast<const char*>(values.data()), values.size_bytes());
}

// Writes `motion` as `stem`.gltf and `stem`.bin in `dir`: its joints as
// nodes (static translation: the frame-0 local position; the root's
// animated), one animation named `animation` with a rotation channel per
// joint, keys at the motion's frames.
fs::path write_gltf(const Motion& motion, const fs::path& dir, const std::string& stem, const std::string& animation) {
  using nlohmann::json;
  const std::size_t joints = motion.joint_count(), frames = motion.frame_count;
  std::string bin;
  json accessors = json::array(), views = json::array(), nodes = json::array(), channels = json::array(),
       samplers = json::array();
  auto add_accessor = [&](std::span<const float> values, const char* type, std::size_t count, json extra) {
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", values.size_bytes()}});
    append_floats(bin, values);
    json accessor = {{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", count}, {"type", type}};
    accessor.update(extra);
    accessors.push_back(accessor);
    return accessors.size() - 1;
  };
  std::vector<float> times(frames);
  for (std::size_t f = 0; f < frames; ++f) times[f] = float(f) / motion.fps;
  const std::size_t input = add_accessor(times, "SCALAR", frames, {{"min", {times.front()}}, {"max", {times.back()}}});
  for (std::size_t j = 0; j < joints; ++j) {
    const glm::vec3 p = motion.local_positions[j];
    json node = {{"name", motion.skeleton.names[j]}, {"translation", {p.x, p.y, p.z}}};
    json children = json::array();
    for (std::size_t c = 0; c < joints; ++c) {
      if (motion.skeleton.parents[c] == int(j)) children.push_back(c);
    }
    if (!children.empty()) node["children"] = children;
    nodes.push_back(node);
    std::vector<float> values;
    for (std::size_t f = 0; f < frames; ++f) {
      const glm::quat q = motion.local_rotations[motion.index(std::uint32_t(f), j)];
      values.insert(values.end(), {q.x, q.y, q.z, q.w});
    }
    samplers.push_back({{"input", input}, {"output", add_accessor(values, "VEC4", frames, json::object())}, {"interpolation", "LINEAR"}});
    channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", j}, {"path", "rotation"}}}});
    if (motion.skeleton.parents[j] >= 0) continue;
    values.clear();
    for (std::size_t f = 0; f < frames; ++f) {
      const glm::vec3 q = motion.local_positions[motion.index(std::uint32_t(f), j)];
      values.insert(values.end(), {q.x, q.y, q.z});
    }
    samplers.push_back({{"input", input}, {"output", add_accessor(values, "VEC3", frames, json::object())}, {"interpolation", "LINEAR"}});
    channels.push_back({{"sampler", samplers.size() - 1}, {"target", {{"node", j}, {"path", "translation"}}}});
  }
  const json gltf = {{"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}},
                     {"nodes", nodes}, {"accessors", accessors}, {"bufferViews", views},
                     {"buffers", {{{"byteLength", bin.size()}, {"uri", stem + ".bin"}}}},
                     {"animations", {{{"name", animation}, {"channels", channels}, {"samplers", samplers}}}}};
  std::ofstream(dir / (stem + ".bin"), std::ios::binary) << bin;
  std::ofstream(dir / (stem + ".gltf")) << gltf.dump();
  return dir / (stem + ".gltf");
}

Motion load_bvh_motion(const fs::path& path) {
  const auto bvh = mmvk::load_bvh(path);
  EXPECT_TRUE(bvh.ok()) << bvh.message();
  auto motion = mmvk::motion_from_bvh(*bvh, {});
  EXPECT_TRUE(motion.ok()) << motion.message();
  return std::move(*motion);
}

mmvk::Database build_one(const fs::path& file, const fs::path& dir) {
  const std::string text = R"({"fps": 30, "clips": [{"file": ")" + file.string() + R"("}]})";
  auto manifest = mmvk::parse_manifest_json(text, "one.json", dir);
  EXPECT_TRUE(manifest.ok()) << manifest.message();
  auto database = mmvk::build_database(*manifest);
  EXPECT_TRUE(database.ok()) << database.message();
  return std::move(*database);
}

TEST(SceneImport, BuiltDatabasePosesAgreeWithAssimp) {
  // The database's animation needs a character (hips, legs): a CMU walk
  // written as glTF, its poses read back against assimp's nodes.
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh");
  const fs::path path = write_gltf(walk, dir, "walk", "walk");
  const mmvk::Database database = build_one(path, dir);
  const mmvk::AnimationData* a = database.animation();
  ASSERT_NE(a, nullptr);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), 0);
  ASSERT_NE(scene, nullptr);
  const std::size_t joints = a->joint_count();
  std::vector<glm::quat> rotations(joints);
  std::vector<glm::vec3> translations(joints), world(joints);
  for (const std::uint32_t frame : {0u, a->frame_count / 3, a->frame_count / 2, a->frame_count - 1}) {
    mmvk::sample_pose(*a, frame, rotations, translations);
    mmvk::forward_kinematics_batch(a->skeleton, rotations, translations, std::span(&a->root_positions[frame], 1),
                                   std::span(&a->root_yaws[frame], 1), world);
    const auto expected = assimp_world_positions(*scene, *scene->mAnimations[0], frame / 30.0);
    for (std::size_t j = 0; j < joints; ++j) {
      EXPECT_LT(glm::length(world[j] - expected.at(a->skeleton.names[j])), 1e-4f)
          << "frame " << frame << " joint " << a->skeleton.names[j];
    }
  }
}

// The stored poses of two databases of one motion: the least |dot| of their
// rotations, joint by joint (by name: b may have joints above a's, such as
// the scene node that assimp gives a COLLADA skeleton) and frame by frame
// (1 = the same up to sign).
float least_rotation_agreement(const mmvk::Database& a, const mmvk::Database& b) {
  const mmvk::AnimationData *pa = a.animation(), *pb = b.animation();
  if (pa == nullptr || pb == nullptr || pa->frame_count != pb->frame_count) return 0.0f;
  float least = 1.0f;
  for (std::size_t j = 0; j < pa->joint_count(); ++j) {
    const int k = pb->skeleton.find(pa->skeleton.names[j]);
    if (k < 0) return 0.0f;
    for (std::size_t f = 0; f < pa->frame_count; ++f) {
      const glm::quat qa = pa->local_rotations[f * pa->joint_count() + j];
      const glm::quat qb = pb->local_rotations[f * pb->joint_count() + std::size_t(k)];
      least = std::min(least, std::abs(glm::dot(qa, qb)));
    }
  }
  return least;
}

// The largest difference of two databases' features (normalized units);
// they have the same frames and dims.
float largest_feature_difference(const mmvk::Database& a, const mmvk::Database& b) {
  EXPECT_EQ(a.frame_count(), b.frame_count());
  EXPECT_EQ(a.dims(), b.dims());
  const auto x = a.features(), y = b.features();
  float worst = x.size() == y.size() ? 0.0f : INFINITY;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) worst = std::max(worst, std::abs(x[i] - y[i]));
  return worst;
}

TEST(SceneImport, GltfFromABvhClipGivesItsFeatures) {
  const fs::path bvh = mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh";
  const fs::path dir = mmvk::test::make_temp_dir();
  const fs::path gltf = write_gltf(load_bvh_motion(bvh), dir, "walk", "walk_veer_left");
  const mmvk::Database from_bvh = build_one(bvh, dir);
  const mmvk::Database from_gltf = build_one(gltf, dir);
  const float worst = largest_feature_difference(from_bvh, from_gltf);
  EXPECT_LT(worst, 1e-3f) << "largest feature difference (normalized units)";
  EXPECT_EQ(from_gltf.clips()[0].metres_per_unit, 1.0f);  // glTF is metres
  EXPECT_GT(least_rotation_agreement(from_bvh, from_gltf), 0.99999f) << "least |dot| of the stored rotations";
}

TEST(SceneImport, SeveralAnimationsAreSeveralClipsNamedAfterThem) {
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh");
  const fs::path first = write_gltf(walk, dir, "a", "stride");
  // Two animations in one file: the second a copy of the first, renamed.
  std::ifstream in(first);
  nlohmann::json gltf = nlohmann::json::parse(in);
  nlohmann::json second = gltf["animations"][0];
  second["name"] = "stride_again";
  gltf["animations"].push_back(second);
  std::ofstream(dir / "two.gltf") << gltf.dump();
  const mmvk::Database database = build_one(dir / "two.gltf", dir);
  ASSERT_EQ(database.clips().size(), 2u);
  EXPECT_EQ(database.clips()[0].name, "stride");
  EXPECT_EQ(database.clips()[1].name, "stride_again");
  // One of them by name; a name the file lacks lists those it has.
  const std::string pick = R"({"clips": [{"file": "two.gltf", "animation": "stride_again"}]})";
  auto manifest = mmvk::parse_manifest_json(pick, "pick.json", dir);
  ASSERT_TRUE(manifest.ok()) << manifest.message();
  const auto picked = mmvk::build_database(*manifest);
  ASSERT_TRUE(picked.ok()) << picked.message();
  ASSERT_EQ(picked->clips().size(), 1u);
  EXPECT_EQ(picked->clips()[0].name, "two");
  manifest->clips[0].animation = "jump";
  const auto missing = mmvk::build_database(*manifest);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("two.gltf: no animation named 'jump'; the file has 'stride', 'stride_again'"),
            std::string::npos)
      << missing.message();
}

TEST(SceneImport, WrongUnitsOrUpAxisOnAGltfAreRefused) {
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh");
  write_gltf(walk, dir, "walk", "walk");
  auto build = [&](const std::string& import) {
    const std::string text = R"({"fps": 30, "import": )" + import + R"(, "clips": ["walk.gltf"]})";
    auto manifest = mmvk::parse_manifest_json(text, "w.json", dir);
    EXPECT_TRUE(manifest.ok()) << manifest.message();
    return mmvk::build_database(*manifest);
  };
  const auto centimetres = build(R"({"metres_per_unit": 100})");  // metres read as if they were hectometres
  ASSERT_FALSE(centimetres.ok());
  EXPECT_NE(centimetres.message().find("walk.gltf (animation 'walk'): implausible import: standing height"),
            std::string::npos) << centimetres.message();
  EXPECT_NE(centimetres.message().find("set \"import\": {\"metres_per_unit\": 1}"), std::string::npos)
      << centimetres.message();
  const auto z_up = build(R"({"up_axis": "z"})");  // glTF is Y-up
  ASSERT_FALSE(z_up.ok());
  EXPECT_NE(z_up.message().find("the body is not upright along +Y"), std::string::npos) << z_up.message();
  EXPECT_NE(z_up.message().find("set \"import\": {\"up_axis\": \"y\"}"), std::string::npos) << z_up.message();
  EXPECT_TRUE(build(R"({"up_axis": "z", "accept_implausible": true})").ok());
  EXPECT_TRUE(build(R"({"up_axis": "y"})").ok());
}

// --- A COLLADA file written from a BVH clip --------------------------------

// Writes `motion` as a Z-up COLLADA file in centimetres (<unit meter="0.01">,
// <up_axis>Z_UP</up_axis>), so that the import's units and axes come from
// the file: each joint a node with a matrix, animated by one 4x4 matrix per
// frame (COLLADA matrices are row-major).
fs::path write_collada(const Motion& motion, const fs::path& dir, const std::string& stem) {
  const std::size_t joints = motion.joint_count(), frames = motion.frame_count;
  // mmvk's Y-up to the file's Z-up: (x, y, z) -> (x, -z, y); assimp undoes it.
  const glm::mat4 to_file = glm::mat4(glm::mat3(glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, -1, 0)));
  auto local = [&](std::size_t f, std::size_t j) {
    const std::size_t i = motion.index(std::uint32_t(f), j);
    glm::mat4 m = glm::mat4_cast(motion.local_rotations[i]);
    m[3] = glm::vec4(motion.local_positions[i] * 100.0f, 1.0f);  // centimetres
    return motion.skeleton.parents[j] < 0 ? to_file * m : m;
  };
  auto row_major = [](const glm::mat4& m) {
    std::string text;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) text += std::to_string(m[c][r]) + " ";
    }
    return text;
  };
  std::string animations, nodes;
  std::vector<std::string> open(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    const std::string& name = motion.skeleton.names[j];
    std::string times, values, interpolation;
    for (std::size_t f = 0; f < frames; ++f) {
      times += std::to_string(double(f) / motion.fps) + " ";
      values += row_major(local(f, j));
      interpolation += "LINEAR ";
    }
    const std::string n = std::to_string(frames), n16 = std::to_string(16 * frames);
    animations += "<animation id=\"a_" + name + "\">"
      "<source id=\"" + name + "_in\"><float_array id=\"" + name + "_in_a\" count=\"" + n + "\">" + times +
      "</float_array><technique_common><accessor source=\"#" + name + "_in_a\" count=\"" + n +
      "\" stride=\"1\"><param name=\"TIME\" type=\"float\"/></accessor></technique_common></source>"
      "<source id=\"" + name + "_out\"><float_array id=\"" + name + "_out_a\" count=\"" + n16 + "\">" + values +
      "</float_array><technique_common><accessor source=\"#" + name + "_out_a\" count=\"" + n +
      "\" stride=\"16\"><param name=\"TRANSFORM\" type=\"float4x4\"/></accessor></technique_common></source>"
      "<source id=\"" + name + "_ip\"><Name_array id=\"" + name + "_ip_a\" count=\"" + n + "\">" + interpolation +
      "</Name_array><technique_common><accessor source=\"#" + name + "_ip_a\" count=\"" + n +
      "\" stride=\"1\"><param name=\"INTERPOLATION\" type=\"name\"/></accessor></technique_common></source>"
      "<sampler id=\"" + name + "_s\"><input semantic=\"INPUT\" source=\"#" + name + "_in\"/>"
      "<input semantic=\"OUTPUT\" source=\"#" + name + "_out\"/><input semantic=\"INTERPOLATION\" source=\"#" +
      name + "_ip\"/></sampler><channel source=\"#" + name + "_s\" target=\"" + name + "/transform\"/></animation>\n";
  }
  // Nodes nest: joints are depth-first with parents first.
  std::function<std::string(std::size_t)> node = [&](std::size_t j) {
    const std::string& name = motion.skeleton.names[j];
    std::string text = "<node id=\"" + name + "\" name=\"" + name + "\" sid=\"" + name +
                       "\" type=\"JOINT\"><matrix sid=\"transform\">" + row_major(local(0, j)) + "</matrix>";
    for (std::size_t c = 0; c < joints; ++c) {
      if (motion.skeleton.parents[c] == int(j)) text += node(c);
    }
    return text + "</node>";
  };
  std::ofstream(dir / (stem + ".dae"))
      << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" "
         "version=\"1.4.1\"><asset><unit name=\"centimeter\" meter=\"0.01\"/><up_axis>Z_UP</up_axis></asset>"
         "<library_animations>" << animations << "</library_animations><library_visual_scenes><visual_scene id=\"scene\">"
      << node(0) << "</visual_scene></library_visual_scenes><scene><instance_visual_scene url=\"#scene\"/></scene></COLLADA>\n";
  return dir / (stem + ".dae");
}

// --- An FBX file written from a BVH clip -----------------------------------

std::string fbx_number(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.9g", value);
  return text;
}

std::string fbx_array(const std::string& name, const std::vector<std::string>& values) {
  std::string text = "  " + name + ": *" + std::to_string(values.size()) + " {\n   a: ";
  for (std::size_t i = 0; i < values.size(); ++i) text += (i ? "," : "") + values[i];
  return text + "\n  }\n";
}

// Writes `motion` as an ASCII FBX 7.4 file, Z-up with -Y in front (as
// Blender writes) and in centimetres (UnitScaleFactor 1), so that the
// import's units and axes come from the file's GlobalSettings: each joint a
// LimbNode model, animated by translation and Euler XYZ rotation curves with
// a key per frame. (assimp 5.2's own FBX exporter cannot make it: its binary
// output does not read back, and its ASCII output keeps 1 to 3 keys.)
fs::path write_fbx(const Motion& motion, const fs::path& dir, const std::string& stem) {
  const std::size_t joints = motion.joint_count(), frames = motion.frame_count;
  // mmvk's Y-up to the file's Z-up: (x, y, z) -> (x, -z, y), as for COLLADA.
  const glm::mat3 to_file(glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), glm::vec3(0, -1, 0));
  constexpr double kTicksPerSecond = 46186158000.0;  // FBX KTime
  std::vector<std::string> times;
  for (std::size_t f = 0; f < frames; ++f) times.push_back(std::to_string(std::llround(f / motion.fps * kTicksPerSecond)));
  std::string objects, connections;
  long long next_id = 1000;
  const long long stack = next_id++, layer = next_id++;
  objects += " AnimationStack: " + std::to_string(stack) + ", \"AnimStack::" + stem + "\", \"\" {\n  Properties70:  {\n"
             "   P: \"LocalStop\", \"KTime\", \"Time\", \"\"," + times.back() + "\n  }\n }\n"
             " AnimationLayer: " + std::to_string(layer) + ", \"AnimLayer::BaseLayer\", \"\" {\n }\n";
  connections += " C: \"OO\"," + std::to_string(layer) + "," + std::to_string(stack) + "\n";
  std::vector<long long> model(joints);
  for (long long& id : model) id = next_id++;
  for (std::size_t j = 0; j < joints; ++j) {
    // [T, R][x, y, z][frame]: centimetres and degrees in the file's axes.
    std::vector<std::string> values[2][3];
    for (std::size_t f = 0; f < frames; ++f) {
      const std::size_t i = motion.index(std::uint32_t(f), j);
      glm::mat3 rotation = glm::mat3_cast(motion.local_rotations[i]);
      glm::vec3 translation = motion.local_positions[i] * 100.0f;
      if (motion.skeleton.parents[j] < 0) rotation = to_file * rotation, translation = to_file * translation;
      float z = 0, y = 0, x = 0;  // R = Rz * Ry * Rx: FBX's default rotation order, XYZ
      glm::extractEulerAngleZYX(glm::mat4(rotation), z, y, x);
      const glm::vec3 degrees = glm::degrees(glm::vec3(x, y, z));
      for (int a = 0; a < 3; ++a) values[0][a].push_back(fbx_number(translation[a]));
      for (int a = 0; a < 3; ++a) values[1][a].push_back(fbx_number(degrees[a]));
    }
    const std::string id = std::to_string(model[j]);
    const char* property[2] = {"Lcl Translation", "Lcl Rotation"};
    objects += " Model: " + id + ", \"Model::" + motion.skeleton.names[j] + "\", \"LimbNode\" {\n  Version: 232\n"
               "  Properties70:  {\n";
    for (int k = 0; k < 2; ++k) {
      objects += "   P: \"" + std::string(property[k]) + "\", \"" + property[k] + "\", \"\", \"A\"," + values[k][0][0] +
                 "," + values[k][1][0] + "," + values[k][2][0] + "\n";
    }
    objects += "  }\n }\n";
    const int parent = motion.skeleton.parents[j];
    connections += " C: \"OO\"," + id + "," + (parent < 0 ? std::string("0") : std::to_string(model[parent])) + "\n";
    for (int k = 0; k < 2; ++k) {
      const std::string node = std::to_string(next_id++);
      objects += " AnimationCurveNode: " + node + ", \"AnimCurveNode::" + (k ? "R" : "T") + "\", \"\" {\n }\n";
      connections += " C: \"OO\"," + node + "," + std::to_string(layer) + "\n C: \"OP\"," + node + "," + id + ", \"" +
                     property[k] + "\"\n";
      for (int a = 0; a < 3; ++a) {
        const std::string curve = std::to_string(next_id++);
        objects += " AnimationCurve: " + curve + ", \"AnimCurve::\", \"\" {\n  Default: 0\n  KeyVer: 4008\n" +
                   fbx_array("KeyTime", times) + fbx_array("KeyValueFloat", values[k][a]) +
                   fbx_array("KeyAttrFlags", {"4"}) + fbx_array("KeyAttrDataFloat", {"0", "0", "0", "0"}) +
                   fbx_array("KeyAttrRefCount", {std::to_string(frames)}) + " }\n";
        connections += " C: \"OP\"," + curve + "," + node + ", \"d|" + std::string(1, char('X' + a)) + "\"\n";
      }
    }
  }
  const fs::path path = dir / (stem + ".fbx");
  std::ofstream(path) << "; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n FBXHeaderVersion: 1003\n FBXVersion: 7400\n}\n"
                         "GlobalSettings:  {\n Version: 1000\n Properties70:  {\n"
                         "  P: \"UpAxis\", \"int\", \"Integer\", \"\",2\n  P: \"UpAxisSign\", \"int\", \"Integer\", \"\",1\n"
                         "  P: \"FrontAxis\", \"int\", \"Integer\", \"\",1\n  P: \"FrontAxisSign\", \"int\", \"Integer\", \"\",-1\n"
                         "  P: \"CoordAxis\", \"int\", \"Integer\", \"\",0\n  P: \"CoordAxisSign\", \"int\", \"Integer\", \"\",1\n"
                         "  P: \"UnitScaleFactor\", \"double\", \"Number\", \"\",1\n }\n}\n"
                      << "Objects:  {\n" << objects << "}\nConnections:  {\n" << connections << "}\n";
  return path;
}

// The COLLADA and FBX files above: units and axes from the file.
TEST(SceneImport, ColladaAndFbxInCentimetresZUpFromABvhClipGiveItsFeatures) {
  const fs::path bvh = mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh";
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(bvh);
  const mmvk::Database from_bvh = build_one(bvh, dir);
  struct Written {
    fs::path file;
    float metres_per_unit;  // as the import records it: assimp scales COLLADA to metres itself
    std::string units_from, axes_from;
  };
  const Written files[] = {
      {write_collada(walk, dir, "walk"), 1.0f, "COLLADA <unit> (applied by assimp)", "COLLADA <up_axis> (applied by assimp)"},
      {write_fbx(walk, dir, "walk"), 0.01f, "FBX UnitScaleFactor 1 (centimetres per unit)",
       "FBX UpAxis 2 (0 = X, 1 = Y, 2 = Z), UpAxisSign 1"}};
  for (const Written& written : files) {
    SCOPED_TRACE(written.file.string());
    const mmvk::Database from_file = build_one(written.file, dir);
    // Values written with 6 decimals (COLLADA) or 9 digits (FBX) in
    // centimetres; FBX's rotations as Euler angles.
    EXPECT_LT(largest_feature_difference(from_bvh, from_file), 2e-3f) << "largest feature difference (normalized units)";
    EXPECT_GT(least_rotation_agreement(from_bvh, from_file), 0.9999f) << "least |dot| of the stored rotations";
    EXPECT_EQ(from_file.clips()[0].metres_per_unit, written.metres_per_unit);
    EXPECT_EQ(from_file.clips()[0].units_from, written.units_from);
    EXPECT_EQ(from_file.clips()[0].axes_from, written.axes_from);
  }
}

TEST(SceneImport, CliBuildsAGltfFileAsABvhFile) {
  const auto cli = mmvk::test::cli_binary();
  if (!cli) GTEST_SKIP() << "no mmvk command line in this build";
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh");
  const fs::path gltf = write_gltf(walk, dir, "walk", "walk");
  const auto built = mmvk::test::run_command(cli->string() + " build " + gltf.string() + " -o " +
                                             (dir / "walk.mmdb").string() + " --fps 30");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const auto inspected = mmvk::test::run_command(cli->string() + " inspect " + (dir / "walk.mmdb").string());
  ASSERT_EQ(inspected.exit_code, 0) << inspected.output;
  EXPECT_NE(inspected.output.find("walk"), std::string::npos) << inspected.output;
}

// --- assimp in a child process ---------------------------------------------

TEST(SceneImport, TheChildProcessGivesTheSameImportAsThisProcess) {
  const fs::path dir = mmvk::test::make_temp_dir();
  const Motion walk = load_bvh_motion(mmvk::test::test_source_dir() / "../host/crowd/data/cmu16/16_23.bvh");
  const fs::path gltf = write_gltf(walk, dir, "walk", "walk");
  mmvk::SceneImportOptions here;
  here.isolate = false;
  const auto child = mmvk::import_scene(gltf, {});
  const auto local = mmvk::import_scene(gltf, here);
  ASSERT_TRUE(child.ok()) << child.message();
  ASSERT_TRUE(local.ok()) << local.message();
  EXPECT_EQ(child->metres_per_unit, local->metres_per_unit);
  EXPECT_EQ(child->units_from, local->units_from);
  EXPECT_EQ(child->axes_from, local->axes_from);
  ASSERT_EQ(child->animations.size(), local->animations.size());
  for (std::size_t a = 0; a < local->animations.size(); ++a) {
    const Motion &x = child->animations[a].motion, &y = local->animations[a].motion;
    EXPECT_EQ(child->animations[a].name, local->animations[a].name);
    EXPECT_EQ(x.fps, y.fps);
    EXPECT_EQ(x.frame_count, y.frame_count);
    EXPECT_EQ(x.skeleton.names, y.skeleton.names);
    EXPECT_EQ(x.skeleton.parents, y.skeleton.parents);
    EXPECT_EQ(x.skeleton.rest_offsets, y.skeleton.rest_offsets);
    EXPECT_EQ(x.local_positions, y.local_positions);
    EXPECT_EQ(x.local_rotations, y.local_rotations);
  }
  // A failed read's message comes back from the child unchanged.
  std::ofstream(dir / "fake.fbx") << "not an fbx at all";
  const auto fake_child = mmvk::import_scene(dir / "fake.fbx", {});
  const auto fake_local = mmvk::import_scene(dir / "fake.fbx", here);
  ASSERT_FALSE(fake_child.ok());
  EXPECT_EQ(fake_child.message(), fake_local.message());
}

// A COLLADA triangle list with a stray letter in its indices ("2x"): assimp
// 5.2.5 reads it allocating without bound (over 1 GB in 5 s). In the child
// process that is an error naming the file, within the limits given.
TEST(SceneImport, AFileOnWhichAssimpRunsAwayIsAnErrorNamingIt) {
  const fs::path dir = mmvk::test::make_temp_dir();
  const fs::path dae = dir / "runaway.dae";
  std::ofstream(dae) << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="1"/><up_axis>Y_UP</up_axis></asset>
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array><technique_common>
<accessor source="#pa" count="3" stride="3"><param name="X" type="float"/><param name="Y" type="float"/>
<param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2x 1</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>
)";
  mmvk::SceneImportOptions options;
  options.timeout_seconds = 3.0;
  options.memory_budget_bytes = std::uint64_t{256} << 20;
  const auto imported = mmvk::import_scene(dae, options);
  ASSERT_FALSE(imported.ok());
  EXPECT_EQ(imported.message().rfind(dae.string() + ": ", 0), 0u) << imported.message();
  EXPECT_NE(imported.message().find("assimp"), std::string::npos) << imported.message();
  options.timeout_seconds = 0.0;
  const auto no_time = mmvk::import_scene(dae, options);
  ASSERT_FALSE(no_time.ok());
  EXPECT_NE(no_time.message().find("timeout_seconds and memory_budget_bytes must be positive"), std::string::npos)
      << no_time.message();
}

TEST(SceneImport, ErrorsNameTheFile) {
  const fs::path dir = mmvk::test::make_temp_dir();
  std::ofstream(dir / "fake.fbx") << "not an fbx at all";
  const auto fake = mmvk::import_scene(dir / "fake.fbx", {});
  ASSERT_FALSE(fake.ok());
  EXPECT_NE(fake.message().find("fake.fbx: assimp could not read it"), std::string::npos) << fake.message();
  const fs::path still = kModels / "glTF2/BoxTextured-glTF/BoxTextured.gltf";
  MMVK_REQUIRE_TEST_MODEL(still);
  const auto box = mmvk::import_scene(still, {});
  ASSERT_FALSE(box.ok());
  EXPECT_NE(box.message().find("BoxTextured.gltf: no animation in the file"), std::string::npos) << box.message();
}

// A one-joint glTF whose rotation keys are at `times` (seconds, any order).
fs::path write_keys_gltf(const fs::path& dir, const std::string& stem, const std::vector<float>& times) {
  using nlohmann::json;
  std::string bin;
  append_floats(bin, times);
  std::vector<float> rotations;
  for (std::size_t k = 0; k < times.size(); ++k) rotations.insert(rotations.end(), {0.0f, 0.0f, 0.0f, 1.0f});
  append_floats(bin, rotations);
  const auto [low, high] = std::minmax_element(times.begin(), times.end());
  const json gltf = {
      {"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}}, {"nodes", {{{"name", "Hips"}}}},
      {"buffers", {{{"byteLength", bin.size()}, {"uri", stem + ".bin"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 4 * times.size()}},
                       {{"buffer", 0}, {"byteOffset", 4 * times.size()}, {"byteLength", 16 * times.size()}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", times.size()}, {"type", "SCALAR"},
                      {"min", {*low}}, {"max", {*high}}},
                     {{"bufferView", 1}, {"componentType", 5126}, {"count", times.size()}, {"type", "VEC4"}}}},
      {"animations", {{{"name", "a"}, {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}}}},
                       {"samplers", {{{"input", 0}, {"output", 1}}}}}}}};
  std::ofstream(dir / (stem + ".bin"), std::ios::binary) << bin;
  std::ofstream(dir / (stem + ".gltf")) << gltf.dump();
  return dir / (stem + ".gltf");
}

TEST(SceneImport, HostileFilesEndInErrors) {
  const fs::path dir = mmvk::test::make_temp_dir();
  mmvk::SceneImportOptions options;
  options.fps = 30.0f;
  // A FIFO under a scene name: refused before assimp would block on it.
  ASSERT_EQ(::mkfifo((dir / "pipe.fbx").c_str(), 0600), 0);
  const auto pipe = mmvk::import_scene(dir / "pipe.fbx", options);
  ASSERT_FALSE(pipe.ok());
  EXPECT_NE(pipe.message().find("pipe.fbx: not a regular file"), std::string::npos) << pipe.message();
  // A claimed ten-million-second animation: an error, not 300 million frames.
  const auto huge = mmvk::import_scene(write_keys_gltf(dir, "huge", {0.0f, 1e7f}), options);
  ASSERT_FALSE(huge.ok());
  EXPECT_NE(huge.message().find("huge.gltf: animation 'a': 1e+07 s at 30 fps is 3e+08 frames of 1 joints, over the "
                                "limit of 33554432 samples"),
            std::string::npos)
      << huge.message();
  // Keys out of order: whatever assimp makes of them, an answer.
  const auto shuffled = mmvk::import_scene(write_keys_gltf(dir, "shuffled", {1.0f, 0.0f, 0.5f}), options);
  if (shuffled.ok()) {
    EXPECT_EQ(shuffled->animations.size(), 1u);
  }
  // A truncated FBX.
  const fs::path fbx = kModels / "FBX/animation_with_skeleton.fbx";
  MMVK_REQUIRE_TEST_MODEL(fbx);
  std::ifstream in(fbx, std::ios::binary);
  std::string head(4096, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  std::ofstream(dir / "cut.fbx", std::ios::binary) << head;
  const auto cut = mmvk::import_scene(dir / "cut.fbx", options);
  ASSERT_FALSE(cut.ok());
  EXPECT_NE(cut.message().find("cut.fbx: assimp could not read it"), std::string::npos) << cut.message();
}

}  // namespace
