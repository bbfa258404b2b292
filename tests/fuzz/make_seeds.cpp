// Writes the fuzzers' seed corpora: small valid inputs made by the library
// itself, so the seeds follow the formats as they change.
//   make_seeds OUT_DIR [MALFORMED_BVH_DIR]
// OUT_DIR/<target>/ gets: bvh (a generated walk, plus the malformed-BVH test
// corpus when given), mmdb and mmdb_repair (a database built from the walk),
// json (a manifest and the default schema, each behind its selector byte),
// cluster_table (a table trained on fixed_database.hpp's), query (query rows).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mmvk/bvh.hpp"
#include "mmvk/cluster_table.hpp"
#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/feature_schema.hpp"
#include "fixed_database.hpp"

namespace fs = std::filesystem;

namespace {

// A 40-frame, 30 fps walk of a 5-joint skeleton whose names resolve to the
// default schema's bone roles (hips, upper legs, feet).
std::string walk_bvh() {
  std::string text =
      "HIERARCHY\nROOT Hips\n{\n OFFSET 0 100 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
      " JOINT UpperLeg_L\n {\n  OFFSET 10 -5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  JOINT Foot_L\n  {\n   OFFSET 0 -90 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "   End Site\n   {\n    OFFSET 0 -5 10\n   }\n  }\n }\n"
      " JOINT UpperLeg_R\n {\n  OFFSET -10 -5 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  JOINT Foot_R\n  {\n   OFFSET 0 -90 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "   End Site\n   {\n    OFFSET 0 -5 10\n   }\n  }\n }\n}\n"
      "MOTION\nFrames: 40\nFrame Time: 0.0333333\n";
  char line[256];
  for (int f = 0; f < 40; ++f) {
    const double swing = 25.0 * std::sin(f * 0.3);
    std::snprintf(line, sizeof(line), "0 100 %.2f 0 0 %.2f 0 %.2f 0 0 0 0 0 %.2f 0 0 0 0\n", f * 4.0, f * 1.5, swing,
                  -swing);
    text += line;
  }
  return text;
}

bool write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  return bool(out);
}

std::string read(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_seeds OUT_DIR [MALFORMED_BVH_DIR]\n");
    return 2;
  }
  const fs::path out = argv[1];
  const std::string bvh = walk_bvh();
  bool ok = write(out / "bvh" / "walk.bvh", bvh);
  if (argc > 2) {
    for (const fs::directory_entry& entry : fs::directory_iterator(argv[2])) {
      ok = ok && write(out / "bvh" / entry.path().filename(), read(entry.path()));
    }
  }

  mmvk::Result<mmvk::BvhFile> file = mmvk::parse_bvh(bvh, "walk.bvh");
  if (!file.ok()) return std::fprintf(stderr, "%s\n", file.message().c_str()), 1;
  mmvk::Result<mmvk::Motion> motion = mmvk::motion_from_bvh(*file, {});
  if (!motion.ok()) return std::fprintf(stderr, "%s\n", motion.message().c_str()), 1;
  std::vector<mmvk::MotionClip> clips(1);
  clips[0].meta.file = "walk.bvh";
  clips[0].meta.name = "walk";
  clips[0].meta.tags = {"walk"};
  clips[0].motion = std::move(*motion);
  mmvk::MotionBuildSettings settings;
  settings.edge_rule = mmvk::EdgeRule::Clamp;
  mmvk::Result<mmvk::Database> db = mmvk::build_database_from_motions(clips, settings);
  if (!db.ok()) return std::fprintf(stderr, "%s\n", db.message().c_str()), 1;
  const std::string mmdb = mmvk::serialize_database(*db);
  ok = ok && write(out / "mmdb" / "walk.mmdb", mmdb);
  ok = ok && write(out / "mmdb_repair" / "walk.mmdb", mmdb);
  ok = ok && write(out / "search_diff" / "walk", std::string(8, '\x5a') + mmdb);

  ok = ok && write(out / "json" / "schema.json", std::string(1, '\0') + mmvk::schema_to_json(mmvk::default_schema()));
  ok = ok && write(out / "json" / "manifest.json",
                   "\1{\"fps\": 30, \"edge_rule\": \"clamp\", \"mirror\": true, \"import\": {\"metres_per_unit\": 0.01},"
                   " \"clips\": [{\"file\": \"walk.bvh\", \"name\": \"walk\", \"tags\": [\"walk\"], \"loop\": true,"
                   " \"cost_multiplier\": 1.5, \"cost_bias\": 0.1, \"do_not_use\": [[0.0, 0.2]],"
                   " \"block_transition\": [[1.0, 1.1]]}]}");

  mmvk::KMeansParams params;
  params.clusters = 2;
  mmvk::Result<mmvk::ClusterTable> table = mmvk::train_cluster_table(mmvk::fuzz::fixed_database(), params);
  if (!table.ok()) return std::fprintf(stderr, "%s\n", table.message().c_str()), 1;
  const fs::path table_path = out / "cluster_table" / "walk.mmkc";
  fs::create_directories(table_path.parent_path());
  ok = ok && mmvk::save_cluster_table(*table, table_path).ok();

  const std::span<const float> rows = db->features().first(3 * std::size_t{db->dims()});
  ok = ok && write(out / "query" / "rows.f32", std::string(reinterpret_cast<const char*>(rows.data()), rows.size_bytes()));
  if (!ok) std::fprintf(stderr, "make_seeds: could not write every seed under %s\n", out.c_str());
  return ok ? 0 : 1;
}
