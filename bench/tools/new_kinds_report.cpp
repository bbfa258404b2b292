// Cross-size retrieval for limb_vector on the Bandai locomotion set
// (bench/RESULTS.md, "Motion quality", "Feature kinds"): every clip scaled by
// 0.8 (bones and root path); each scaled frame's features, normalized like
// the unscaled database, are searched in the unscaled database; top-1
// agreement with the unscaled frame's own query, limb_vector schema vs raw
// bone positions. (The phase figures come from
// tests/data/new_kinds_data_test.cpp.)
// Usage: mmvk_new_kinds_report [data dir] [stride]   (default ../shared/data, 5)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/search/reference_search.hpp"

namespace {

using namespace mmvk;

struct Clips {
  std::vector<MotionClip> unscaled;
  std::vector<MotionClip> scaled;
  Manifest manifest;
};

Result<Clips> load(const std::filesystem::path& dir, float scale) {
  Clips out;
  MMVK_ASSIGN_OR_RETURN(out.manifest, manifest_from_directory(dir));
  for (const ManifestClip& meta : out.manifest.clips) {
    MMVK_ASSIGN_OR_RETURN(BvhFile file, load_bvh(meta.file));
    MMVK_ASSIGN_OR_RETURN(Motion motion, motion_from_bvh(file, out.manifest.import));
    if (out.manifest.fps > 0.0f) {
      MMVK_ASSIGN_OR_RETURN(motion, resample(motion, out.manifest.fps));
    }
    MotionClip clip;
    clip.meta = meta;
    clip.motion = motion;
    out.unscaled.push_back(clip);
    for (glm::vec3& offset : clip.motion.skeleton.rest_offsets) offset *= scale;
    for (glm::vec3& position : clip.motion.local_positions) position *= scale;
    out.scaled.push_back(std::move(clip));
  }
  return out;
}

Result<Database> build(const std::vector<MotionClip>& clips, const Manifest& manifest, const std::string& schema_json) {
  MotionBuildSettings settings;
  MMVK_ASSIGN_OR_RETURN(settings.schema, parse_schema_json(schema_json, "report schema"));
  settings.character_root = manifest.character_root;
  settings.edge_rule = EdgeRule::Clamp;  // every frame a candidate: agreement is over all frames
  settings.animation.enabled = false;
  return build_database_from_motions(clips, settings);
}

// Top-1 agreement: queries from every `stride`-th scaled frame, normalized
// with the unscaled database, against the unscaled frame's own top-1.
Result<double> agreement(const Clips& clips, const std::string& schema_json, std::uint32_t stride) {
  MMVK_ASSIGN_OR_RETURN(Database base, build(clips.unscaled, clips.manifest, schema_json));
  MMVK_ASSIGN_OR_RETURN(Database small, build(clips.scaled, clips.manifest, schema_json));
  const std::uint32_t dims = base.dims();
  std::vector<float> unscaled_queries, scaled_queries, raw(dims), normalized(dims);
  for (std::uint32_t f = 0; f < base.frame_count(); f += stride) {
    const std::span<const float> row = base.row(f);
    unscaled_queries.insert(unscaled_queries.end(), row.begin(), row.end());
    // The scaled frame's raw values, normalized like the unscaled database.
    for (std::uint32_t d = 0; d < dims; ++d) {
      raw[d] = small.row(f)[d] * small.normalization()[d].scale + small.normalization()[d].offset;
    }
    base.normalize(raw, normalized);
    scaled_queries.insert(scaled_queries.end(), normalized.begin(), normalized.end());
  }
  const std::size_t count = unscaled_queries.size() / dims;
  std::vector<Match> expected(count), actual(count);
  ReferenceSearch search(base);
  MMVK_TRY(search.search(QueryBatch{.features = unscaled_queries, .params = {}, .size = count}, 1, expected));
  MMVK_TRY(search.search(QueryBatch{.features = scaled_queries, .params = {}, .size = count}, 1, actual));
  std::size_t same = 0;
  for (std::size_t q = 0; q < count; ++q) same += expected[q].frame == actual[q].frame;
  std::printf("  %zu queries, %zu agree\n", count, same);
  return double(same) / double(count);
}

}  // namespace

int main(int argc, char** argv) {
  const std::filesystem::path data = argc > 1 ? argv[1] : MMVK_DEFAULT_DATA_DIR;
  const std::uint32_t stride = argc > 2 ? static_cast<std::uint32_t>(std::stoul(argv[2])) : 5u;
  Result<Clips> clips = load(data / "bandai-namco-nc" / "locomotion-normal", 0.8f);
  if (!clips.ok()) {
    std::fprintf(stderr, "%s\n", clips.message().c_str());
    return 1;
  }
  const std::string raw_positions = R"({"channels": [
      {"name": "left_foot", "kind": "bone_position", "bone": "@left_foot"},
      {"name": "right_foot", "kind": "bone_position", "bone": "@right_foot"},
      {"name": "left_hand", "kind": "bone_position", "bone": "@left_hand"},
      {"name": "right_hand", "kind": "bone_position", "bone": "@right_hand"}]})";
  const std::string limbs = R"({"channels": [
      {"name": "left_leg", "kind": "limb_vector", "limb": "left_leg"},
      {"name": "right_leg", "kind": "limb_vector", "limb": "right_leg"},
      {"name": "left_arm", "kind": "limb_vector", "limb": "left_arm"},
      {"name": "right_arm", "kind": "limb_vector", "limb": "right_arm"}]})";
  std::printf("cross-size retrieval, queries from the clips scaled 0.8x, every %u-th frame\n", stride);
  std::printf("raw bone positions (feet, hands):\n");
  Result<double> a = agreement(*clips, raw_positions, stride);
  std::printf("limb vectors (legs, arms):\n");
  Result<double> b = agreement(*clips, limbs, stride);
  if (!a.ok() || !b.ok()) {
    std::fprintf(stderr, "%s\n", (!a.ok() ? a.message() : b.message()).c_str());
    return 1;
  }
  std::printf("top-1 agreement: raw positions %.4f, limb_vector %.4f\n", *a, *b);
  return 0;
}
