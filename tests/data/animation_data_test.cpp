// The animation section on Bandai locomotion: stored poses reproduce the
// import's joint positions (float and 16-bit rotations), mirroring holds for
// animation, contacts are plausible, the section survives a file round trip,
// and the features are the same with or without it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "support/command.hpp"
#include "support/test_data.hpp"

namespace mmvk {
namespace {

const char* kLocomotion = "bandai-namco-nc/locomotion-normal";

// World joint positions of database frames [first, first + count) from the
// stored poses, placed at each frame's own root: the import's model space.
std::vector<glm::vec3> stored_positions(const AnimationData& a, std::uint32_t first, std::uint32_t count) {
  const std::size_t joints = a.joint_count();
  std::vector<glm::quat> rotations(count * joints);
  std::vector<glm::vec3> translations(count * joints);
  std::vector<glm::vec3> roots(count);
  std::vector<float> yaws(count);
  for (std::uint32_t i = 0; i < count; ++i) {
    sample_pose(a, first + i, std::span(rotations).subspan(i * joints, joints),
                std::span(translations).subspan(i * joints, joints));
    roots[i] = a.root_positions[first + i];
    yaws[i] = a.root_yaws[first + i];
  }
  std::vector<glm::vec3> out(count * joints);
  ThreadPool pool(2);
  forward_kinematics_batch(a.skeleton, rotations, translations, roots, yaws, out, &pool);
  return out;
}

std::vector<glm::vec3> import_positions(const Motion& motion) {
  std::vector<glm::vec3> positions(motion.frame_count * motion.joint_count());
  std::vector<glm::quat> rotations(positions.size());
  forward_kinematics_clip(motion, positions, rotations);
  return positions;
}

float max_distance(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
  float worst = 0.0f;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, glm::length(a[i] - b[i]));
  return worst;
}

class AnimationData_ : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto dir = test::find_data_dir();
    if (!dir) return;
    Result<Manifest> manifest = manifest_from_directory(*dir / kLocomotion);
    ASSERT_TRUE(manifest.ok()) << manifest.message();
    // Every fourth clip mirrored too.
    for (std::size_t c = 0; c < manifest->clips.size(); c += 4) manifest->clips[c].mirror = true;
    ThreadPool pool(2);
    BuildOptions options;
    options.pool = &pool;
    Result<Database> built = build_database(*manifest, options);
    ASSERT_TRUE(built.ok()) << built.message();
    database_ = new Database(std::move(*built));
    manifest_ = new Manifest(std::move(*manifest));
  }
  static void TearDownTestSuite() {
    delete database_;
    delete manifest_;
    database_ = nullptr;
    manifest_ = nullptr;
  }
  void SetUp() override {
    MMVK_REQUIRE_DATA_DIR(dir);
    ASSERT_NE(database_, nullptr);
    ASSERT_NE(database_->animation(), nullptr);
  }
  static Database* database_;
  static Manifest* manifest_;
};
Database* AnimationData_::database_ = nullptr;
Manifest* AnimationData_::manifest_ = nullptr;

TEST_F(AnimationData_, ForwardKinematicsOfStoredPosesReproducesTheImport) {
  const AnimationData& a = *database_->animation();
  EXPECT_EQ(a.joint_count(), 22u);
  float worst = 0.0f;
  for (const Clip& clip : database_->clips()) {
    if (clip.mirrored) continue;
    Result<BvhFile> bvh = load_bvh(clip.source);
    ASSERT_TRUE(bvh.ok()) << bvh.message();
    Result<Motion> motion = motion_from_bvh(*bvh, manifest_->import);
    ASSERT_TRUE(motion.ok()) << motion.message();
    ASSERT_EQ(motion->frame_count, clip.frame_count) << clip.source;
    const std::vector<glm::vec3> expected = import_positions(*motion);
    const std::vector<glm::vec3> stored = stored_positions(a, clip.first_frame, clip.frame_count);
    // Every joint but the static scene root above the hips (joint_Root),
    // which the section places at the character root.
    const std::size_t joints = a.joint_count();
    for (std::size_t i = 0; i < expected.size(); ++i) {
      if (i % joints == 0) continue;
      worst = std::max(worst, glm::length(expected[i] - stored[i]));
    }
  }
  EXPECT_EQ(a.skeleton.names[0], "joint_Root");
  EXPECT_EQ(a.skeleton.names[1], "Hips");
  std::printf("worst joint position error over the locomotion set: %.3g m\n", double(worst));
  EXPECT_LT(worst, 1e-4f);
}

TEST_F(AnimationData_, QuantizedRotationsStayWithinATenthOfADegree) {
  const AnimationData& a = *database_->animation();
  DatabaseParts parts = database_->parts();
  parts.animation->encoding = RotationEncoding::Quantized16;
  Result<Database> quantized_db = Database::create(std::move(parts));
  ASSERT_TRUE(quantized_db.ok()) << quantized_db.message();
  const std::string bytes = serialize_database(*quantized_db);
  Result<Database> loaded = deserialize_database(bytes, "quantized.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const AnimationData& q = *loaded->animation();
  ASSERT_EQ(q.local_rotations.size(), a.local_rotations.size());
  double worst_degrees = 0.0;
  for (std::size_t i = 0; i < a.local_rotations.size(); ++i) {
    // The angle of the relative rotation, in double (acos of a float dot
    // product near 1 would measure float rounding, not the quantization).
    const glm::dquat x(a.local_rotations[i]);
    const glm::dquat y(q.local_rotations[i]);
    const glm::dquat d = glm::conjugate(x) * y;
    const double angle = 2.0 * std::atan2(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z), std::abs(d.w));
    worst_degrees = std::max(worst_degrees, angle * 180.0 / 3.14159265358979);
  }
  const float worst_position =
      max_distance(stored_positions(a, 0, a.frame_count), stored_positions(q, 0, q.frame_count));
  std::printf("quantized16: worst rotation error %.4f deg, worst joint position error %.3g m; %zu vs %zu bytes/frame\n",
              worst_degrees, double(worst_position), q.bytes_per_frame_in_file(), a.bytes_per_frame_in_file());
  EXPECT_LT(worst_degrees, 0.1);
  EXPECT_LT(worst_position, 2e-3f);
  EXPECT_LT(q.bytes_per_frame_in_file(), a.bytes_per_frame_in_file());
}

TEST_F(AnimationData_, MirrorHoldsForAnimation) {
  const AnimationData& a = *database_->animation();
  const auto clips = database_->clips();
  std::size_t checked = 0;
  for (std::size_t c = 0; c + 1 < clips.size(); ++c) {
    if (clips[c].mirrored || !clips[c + 1].mirrored) continue;
    const Clip& original = clips[c];
    const Clip& mirrored = clips[c + 1];
    Result<Motion> m = clip_motion(a, database_->fps(), original.first_frame, original.frame_count);
    Result<Motion> mm = clip_motion(a, database_->fps(), mirrored.first_frame, mirrored.frame_count);
    ASSERT_TRUE(m.ok() && mm.ok());
    // mirror o mirror is the identity, bit for bit, on stored animation too.
    Result<Motion> twice = mirror(*m);
    ASSERT_TRUE(twice.ok());
    twice = mirror(*twice);
    ASSERT_TRUE(twice.ok());
    // (Exactly equal values; a zero may come back as -0.)
    EXPECT_TRUE(twice->local_rotations == m->local_rotations) << original.name;
    EXPECT_TRUE(twice->local_positions == m->local_positions) << original.name;
    // The stored mirrored clip is the mirror of the stored original: joint j
    // sits where its partner sat, x negated.
    const std::vector<glm::vec3> p = stored_positions(a, original.first_frame, original.frame_count);
    const std::vector<glm::vec3> pm = stored_positions(a, mirrored.first_frame, mirrored.frame_count);
    const std::size_t joints = a.joint_count();
    float worst = 0.0f;
    for (std::uint32_t f = 0; f < original.frame_count; ++f) {
      for (std::size_t j = 0; j < joints; ++j) {
        glm::vec3 expected = p[f * joints + static_cast<std::size_t>(a.mirror_pairs[j])];
        expected.x = -expected.x;
        worst = std::max(worst, glm::length(pm[f * joints + j] - expected));
      }
    }
    EXPECT_LT(worst, 1e-3f) << original.name;
    // Contacts swap sides (planted, heel and toe).
    for (std::uint32_t f = 0; f < original.frame_count; ++f) {
      const std::uint8_t c0 = a.contacts[original.first_frame + f];
      ASSERT_EQ(a.contacts[mirrored.first_frame + f], mirror_contact_bits(c0)) << original.name << " frame " << f;
    }
    ++checked;
  }
  EXPECT_GT(checked, 30u);
}

TEST_F(AnimationData_, ContactsFollowTheFeet) {
  const AnimationData& a = *database_->animation();
  EXPECT_EQ(a.skeleton.names[static_cast<std::size_t>(a.contact_joints[0])], "Toes_L");
  EXPECT_EQ(a.skeleton.names[static_cast<std::size_t>(a.contact_joints[1])], "Toes_R");
  // On walks and runs each foot is planted for a good part of the time, and
  // both feet are in the air only in running flight phases.
  std::size_t left = 0, right = 0, none = 0;
  for (std::uint8_t c : a.contacts) {
    left += (c & kContactLeft) ? 1 : 0;
    right += (c & kContactRight) ? 1 : 0;
    none += c == 0 ? 1 : 0;
  }
  const double n = a.frame_count;
  std::printf("contacts: left %.1f%%, right %.1f%%, none %.1f%%\n", 100 * left / n, 100 * right / n, 100 * none / n);
  EXPECT_GT(left / n, 0.3);
  EXPECT_GT(right / n, 0.3);
  EXPECT_LT(left / n, 0.8);
  EXPECT_LT(none / n, 0.35);
}

TEST_F(AnimationData_, SurvivesTheFileAndLeavesFeaturesAlone) {
  const std::string bytes = serialize_database(*database_);
  Result<Database> loaded = deserialize_database(bytes, "loco.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  const AnimationData& a = *database_->animation();
  const AnimationData& b = *loaded->animation();
  EXPECT_EQ(b.skeleton.names, a.skeleton.names);
  EXPECT_EQ(b.translated_joints, a.translated_joints);
  EXPECT_EQ(0, std::memcmp(a.local_rotations.data(), b.local_rotations.data(), a.local_rotations.size() * 16));
  EXPECT_EQ(0, std::memcmp(a.local_translations.data(), b.local_translations.data(), a.local_translations.size() * 12));
  EXPECT_EQ(a.root_yaws, b.root_yaws);
  EXPECT_EQ(a.contacts, b.contacts);
  EXPECT_EQ(loaded->content_hash(), database_->content_hash());
  std::printf("bytes per frame: animation %zu (file), features %u; Bandai volume (417,000 frames): %.0f MB of animation\n",
              a.bytes_per_frame_in_file(), database_->dims() * 4, 417000.0 * double(a.bytes_per_frame_in_file()) / 1e6);

  // --no-animation: identical features and hash, no section, a smaller file.
  Result<Manifest> manifest = manifest_from_directory(test::find_data_dir().value() / kLocomotion);
  ASSERT_TRUE(manifest.ok());
  for (std::size_t c = 0; c < manifest->clips.size(); c += 4) manifest->clips[c].mirror = true;
  BuildOptions options;
  options.animation.enabled = false;
  Result<Database> plain = build_database(*manifest, options);
  ASSERT_TRUE(plain.ok()) << plain.message();
  EXPECT_EQ(plain->animation(), nullptr);
  EXPECT_EQ(plain->no_animation_reason(), "built with --no-animation");
  EXPECT_EQ(plain->content_hash(), database_->content_hash());
  EXPECT_LT(serialize_database(*plain).size() + a.frame_count * a.bytes_per_frame_in_file(), bytes.size() + 1);
}

TEST(AnimationBuild, MixedSkeletonsBuildWithoutTheSectionAndSayWhy) {
  MMVK_REQUIRE_DATA_DIR(data);
  Manifest mixed;
  mixed.source = "mixed";
  mixed.fps = 30.0f;
  mixed.clips.resize(2);
  mixed.clips[0].file = data / kLocomotion / "dataset-2_walk_normal_001.bvh";
  mixed.clips[1].file = data / "cmu/amc2bvh-131/131_01.bvh";
  std::string warning;
  BuildOptions options;
  options.animation.warning = [&](const std::string& message) { warning = message; };
  Result<Database> db = build_database(mixed, options);
  ASSERT_TRUE(db.ok()) << db.message();
  EXPECT_EQ(db->animation(), nullptr);
  EXPECT_NE(warning.find("1 clip's hierarchy differs from"), std::string::npos) << warning;
  EXPECT_NE(warning.find("Build each skeleton's clips into a database of its own"), std::string::npos) << warning;
  EXPECT_NE(warning.find("131_01.bvh"), std::string::npos) << warning;
  EXPECT_NE(warning.find("walk_normal_001.bvh"), std::string::npos) << warning;
  // The database keeps the reason, so `inspect` and the crowd give it
  // rather than guess.
  const std::string& reason = db->no_animation_reason();
  EXPECT_NE(reason.find("1 clip's hierarchy differs from"), std::string::npos) << reason;
  EXPECT_NE(reason.find("131_01.bvh"), std::string::npos) << reason;
  Result<Database> loaded = deserialize_database(serialize_database(*db), "mixed.mmdb");
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  EXPECT_EQ(loaded->no_animation_reason(), reason);
}

int run(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()); }

TEST(AnimationCommandLine, BuildInspectExport) {
  MMVK_REQUIRE_DATA_DIR(data);
  const auto cli = test::cli_binary();
  if (!cli) GTEST_SKIP() << "mmvk not built (MMVK_BUILD_HOST=OFF)";
  const std::string mmvk = cli->string();
  const auto dir = test::make_temp_dir();
  const std::string walk = (data / kLocomotion / "dataset-2_walk_normal_003.bvh").string();
  std::ofstream(dir / "m.json") << R"({"clips": [{"file": ")" << walk << R"("}]})";
  const std::string db = (dir / "db.mmdb").string();
  const std::string plain = (dir / "plain.mmdb").string();
  const std::string quantized = (dir / "q.mmdb").string();
  const std::string manifest = (dir / "m.json").string();
  ASSERT_EQ(run(mmvk + " build " + manifest + " -o " + db + " --no-progress"), 0);
  ASSERT_EQ(run(mmvk + " build " + manifest + " -o " + plain + " --no-animation --no-progress"), 0);
  ASSERT_EQ(run(mmvk + " build " + manifest + " -o " + quantized + " --quantize-rotations --no-progress"), 0);
  Result<Database> loaded = load_database(db);
  ASSERT_TRUE(loaded.ok()) << loaded.message();
  ASSERT_NE(loaded->animation(), nullptr);
  const AnimationData& a = *loaded->animation();
  Result<Database> loaded_plain = load_database(plain);
  ASSERT_TRUE(loaded_plain.ok());
  EXPECT_EQ(loaded_plain->animation(), nullptr);
  // The section costs its bytes per frame plus a skeleton header of under 2 KB.
  const std::uintmax_t section = std::filesystem::file_size(db) - std::filesystem::file_size(plain);
  EXPECT_GE(section, std::uintmax_t{a.frame_count} * a.bytes_per_frame_in_file());
  EXPECT_LT(section, std::uintmax_t{a.frame_count} * a.bytes_per_frame_in_file() + 2048);
  Result<Database> loaded_quantized = load_database(quantized);
  ASSERT_TRUE(loaded_quantized.ok());
  EXPECT_EQ(loaded_quantized->animation()->encoding, RotationEncoding::Quantized16);

  ASSERT_EQ(std::system((mmvk + " inspect --json " + db + " > " + (dir / "i.json").string()).c_str()), 0);
  const nlohmann::json inspect = nlohmann::json::parse(std::ifstream(dir / "i.json"));
  EXPECT_EQ(inspect["animation"]["present"], true);
  EXPECT_EQ(inspect["animation"]["joints"].size(), 22u);
  EXPECT_EQ(inspect["animation"]["joints"][1]["name"], "Hips");
  EXPECT_EQ(inspect["animation"]["bytes_per_frame_file"], a.bytes_per_frame_in_file());
  ASSERT_EQ(std::system((mmvk + " inspect --json " + plain + " > " + (dir / "p.json").string()).c_str()), 0);
  const nlohmann::json plain_inspect = nlohmann::json::parse(std::ifstream(dir / "p.json"));
  EXPECT_EQ(plain_inspect["animation"]["present"], false);
  EXPECT_EQ(plain_inspect["animation"]["reason"], "built with --no-animation");
  const auto text = test::run_command(mmvk + " inspect " + plain);
  EXPECT_NE(text.output.find("animation: none, features only (built with --no-animation)\n"), std::string::npos)
      << text.output;

  const std::string out = (dir / "anim.f32").string();
  ASSERT_EQ(run(mmvk + " export " + db + " --animation " + out), 0);
  const nlohmann::json sidecar = nlohmann::json::parse(std::ifstream(out + ".json"));
  const std::size_t columns = sidecar["columns"].size();
  EXPECT_EQ(columns, 22u * 4 + a.translated_joints.size() * 3 + 4);
  EXPECT_EQ(sidecar["frames"], a.frame_count);
  ASSERT_EQ(std::filesystem::file_size(out), std::size_t{a.frame_count} * columns * 4);
  std::ifstream in(out, std::ios::binary);
  std::vector<float> values(std::size_t{a.frame_count} * columns);
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * 4));  // little-endian host
  const std::size_t f = 17;
  EXPECT_EQ(values[f * columns + 4 * 5 + 3], a.local_rotations[f * 22 + 5].w);
  EXPECT_EQ(values[f * columns + columns - 2], a.root_yaws[f]);
  EXPECT_EQ(values[f * columns + columns - 1], float(a.contacts[f]));
  // Without animation: a non-zero exit naming the fix.
  EXPECT_NE(run(mmvk + " export " + plain + " --animation " + out), 0);
}

}  // namespace
}  // namespace mmvk
