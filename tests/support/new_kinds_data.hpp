// Databases for the parity suite that use every channel kind of issue 12
// (past trajectory, root turning rate, foot contacts, limb vectors, phase):
// the Bandai locomotion set, and random motion (a Bandai walk with seeded
// random joint rotations and mirrored copies). Search itself does not know
// channel kinds; these check that the values the kinds produce (0/1
// contacts, constant-ish columns, sin/cos pairs) search bit-identically too.
#pragma once

#include <memory>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"

namespace mmvk::test {

// The default 27-d set plus every new kind.
inline FeatureSchema new_kinds_schema() {
  Result<FeatureSchema> extra = parse_schema_json(R"({"channels": [
      {"name": "past_position", "kind": "trajectory_position", "offsets_seconds": [-0.5, -0.25]},
      {"name": "past_direction", "kind": "trajectory_direction", "offsets_seconds": [-0.5]},
      {"name": "turn", "kind": "root_angular_velocity"},
      {"name": "contact", "kind": "foot_contact"},
      {"name": "left_leg", "kind": "limb_vector", "limb": "left_leg"},
      {"name": "right_arm", "kind": "limb_vector", "limb": "right_arm"},
      {"name": "phase", "kind": "phase", "curves": ["@left_foot.speed", "@right_toe.height"], "window_seconds": 0.5}
  ]})", "new_kinds_schema");
  EXPECT_TRUE(extra.ok()) << extra.message();
  FeatureSchema schema = default_schema();
  if (extra.ok()) schema.channels.insert(schema.channels.end(), extra->channels.begin(), extra->channels.end());
  return schema;
}

// The Bandai locomotion set built with `schema` (default options), or
// nullptr after a failure.
inline std::unique_ptr<Database> build_locomotion(const std::filesystem::path& data, const FeatureSchema& schema) {
  Result<Manifest> manifest = manifest_from_directory(data / "bandai-namco-nc" / "locomotion-normal");
  if (!manifest.ok()) {
    ADD_FAILURE() << manifest.message();
    return nullptr;
  }
  manifest->schema = schema;
  ThreadPool pool;
  BuildOptions options;
  options.pool = &pool;
  Result<Database> built = build_database(*manifest, options);
  if (!built.ok()) {
    ADD_FAILURE() << built.message();
    return nullptr;
  }
  return std::make_unique<Database>(std::move(built).value());
}

// The locomotion set with new_kinds_schema(), built once per program.
inline const Database* locomotion_new_kinds_database(const std::filesystem::path& data) {
  static const std::unique_ptr<Database> db = build_locomotion(data, new_kinds_schema());
  return db.get();
}

// Random motion on a real skeleton: a Bandai walk with a seeded random
// rotation added to every joint (a different draw per clip), each clip also
// mirrored; new_kinds_schema(). Built once per program.
inline const Database* random_new_kinds_database(const std::filesystem::path& data) {
  static std::unique_ptr<Database> db;
  static bool tried = false;
  if (!tried) {
    tried = true;
    const std::filesystem::path path = data / "bandai-namco-nc" / "locomotion-normal" / "dataset-2_walk_normal_001.bvh";
    Result<BvhFile> file = load_bvh(path);
    Result<Motion> walk = file.ok() ? motion_from_bvh(*file, ImportOptions{}) : Result<Motion>(file.error());
    if (!walk.ok()) {
      ADD_FAILURE() << walk.message();
      return nullptr;
    }
    std::mt19937_64 rng(1212);
    std::normal_distribution<float> noise(0.0f, 0.08f);
    std::vector<MotionClip> clips;
    for (int c = 0; c < 4; ++c) {
      MotionClip clip;
      clip.motion = *walk;
      // One random rotation per joint, applied on every frame: per-frame
      // noise would make every foot fast and leave no contact to detect.
      const std::size_t joints = clip.motion.joint_count();
      std::vector<glm::quat> bias(joints);
      for (glm::quat& q : bias) q = glm::normalize(glm::quat(1.0f, noise(rng), noise(rng), noise(rng)));
      for (std::size_t i = 0; i < clip.motion.local_rotations.size(); ++i) {
        clip.motion.local_rotations[i] = glm::normalize(clip.motion.local_rotations[i] * bias[i % joints]);
      }
      clip.meta.file = path;
      clip.meta.name = "random" + std::to_string(c);
      clip.meta.loop = c % 2 == 1;
      Result<Motion> mirrored = mirror(clip.motion);
      if (!mirrored.ok()) {
        ADD_FAILURE() << mirrored.message();
        return nullptr;
      }
      MotionClip copy = clip;
      copy.motion = std::move(*mirrored);
      copy.mirrored = true;
      clips.push_back(std::move(clip));
      clips.push_back(std::move(copy));
    }
    MotionBuildSettings settings;
    settings.schema = new_kinds_schema();
    settings.edge_rule = EdgeRule::Clamp;  // the short clips keep their edge frames as candidates
    Result<Database> built = build_database_from_motions(clips, settings);
    if (!built.ok()) {
      ADD_FAILURE() << built.message();
      return nullptr;
    }
    db = std::make_unique<Database>(std::move(built).value());
  }
  return db.get();
}

}  // namespace mmvk::test
