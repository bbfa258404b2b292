// Writes the fuzzers' seed corpora: small valid inputs made by the library
// itself, so the seeds follow the formats as they change.
//   make_seeds OUT_DIR [MALFORMED_BVH_DIR]
// OUT_DIR/<target>/ gets: bvh (a generated walk, plus the malformed-BVH test
// corpus when given), mmdb and mmdb_repair (a database built from the walk),
// json (a manifest and the default schema, each behind its selector byte;
// nesting at and past kMaxJsonDepth; a manifest of 3,000 clip objects),
// cluster_table (a table trained on fixed_database.hpp's), query (query rows),
// scenario (a crowd scenario using every field, one of 3,000 agents, one
// nested too deep) and pose_targets (targets on
// the walk database's bones).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/clusters/cluster_table.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/json_check.hpp"
#include "fixed_database.hpp"
#include "walk_database.hpp"

namespace fs = std::filesystem;

namespace {

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
  const std::string bvh = mmvk::fuzz::walk_bvh();
  bool ok = write(out / "bvh" / "walk.bvh", bvh);
  if (argc > 2) {
    for (const fs::directory_entry& entry : fs::directory_iterator(argv[2])) {
      ok = ok && write(out / "bvh" / entry.path().filename(), read(entry.path()));
    }
  }

  mmvk::Result<mmvk::Database> db = mmvk::fuzz::build_walk_database();
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

  // Issue 34: nesting at and past kMaxJsonDepth (the parsers must refuse
  // the deeper one before anything recursive walks it) and arrays of many
  // objects (the strict check was quadratic in them).
  const auto nested = [](std::size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); };
  ok = ok && write(out / "json" / "deep_schema.json",
                   "\1{\"clips\": [\"walk.bvh\"], \"schema\": {\"channels\": " + nested(mmvk::kMaxJsonDepth + 8) + "}}");
  ok = ok && write(out / "json" / "deepest_allowed.json",
                   std::string(1, '\0') + "{\"channels\": " + nested(mmvk::kMaxJsonDepth - 1) + "}");
  std::string clips;
  for (int c = 0; c < 3000; ++c) {
    clips += (c ? ", " : "") + std::string("{\"file\": \"walk.bvh\", \"name\": \"w") + std::to_string(c) + "\"}";
  }
  ok = ok && write(out / "json" / "many_clips.json", "\1{\"fps\": 30, \"clips\": [" + clips + "]}");
  std::string agents;
  for (int a = 0; a < 3000; ++a) {
    agents += (a ? ", " : "") + std::string("{\"start\": [") + std::to_string(a % 50) + ", 1], \"goals\": [[2, 3]]}";
  }
  ok = ok && write(out / "scenario" / "many_agents.json", "{\"agents\": [" + agents + "]}");
  ok = ok && write(out / "scenario" / "deep.json", "{\"agents\": " + nested(mmvk::kMaxJsonDepth + 8) + "}");

  mmvk::KMeansParams params;
  params.clusters = 2;
  mmvk::Result<mmvk::ClusterTable> table = mmvk::train_cluster_table(mmvk::fuzz::fixed_database(), params);
  if (!table.ok()) return std::fprintf(stderr, "%s\n", table.message().c_str()), 1;
  const fs::path table_path = out / "cluster_table" / "walk.mmkc";
  fs::create_directories(table_path.parent_path());
  ok = ok && mmvk::save_cluster_table(*table, table_path).ok();

  ok = ok && write(out / "scenario" / "scenario.json",
                   "{\"world_size_m\": 40, \"wait_s\": 2, "
                   "\"agents\": [{\"start\": [0, 0], \"goals\": [[4, 0], [4, 4]], "
                   "\"speed\": \"run\", \"require_tags\": [\"walk\"], \"exclude_tags\": [\"turn\"], \"wait_s\": 0.5}, "
                   "{\"start\": [1, -2.5], \"goals\": [[-3, 1]], \"speed\": 1.2}]}");
  ok = ok && write(out / "pose_targets" / "targets.json",
                   "{\"targets\": [{\"bone\": \"@left_foot\", \"position\": [0.1, 0.05, 0.2], "
                   "\"velocity\": [0, 0, 1.2]}, {\"bone\": \"@right_foot\", \"position\": [-0.1, 0, -0.1]}]}");

  const std::span<const float> rows = db->features().first(3 * std::size_t{db->dims()});
  ok = ok && write(out / "query" / "rows.f32", std::string(reinterpret_cast<const char*>(rows.data()), rows.size_bytes()));
  if (!ok) std::fprintf(stderr, "make_seeds: could not write every seed under %s\n", out.c_str());
  return ok ? 0 : 1;
}
