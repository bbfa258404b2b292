// The crowd's database cache (default_data.cpp): an entry's name digests
// everything its build read, so editing any of it builds a new entry.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "setup/default_data.hpp"
#include "support/test_data.hpp"

namespace mmvk::crowd {
namespace {

namespace fs = std::filesystem;

// Opens `manifest` through the cache in `cache`; true when it was built.
bool opened_by_building(const fs::path& manifest, const fs::path& cache) {
  bool built = false;
  Result<OpenedDatabase> opened =
      open_database(manifest, cache, [&](const std::string& note) { built |= note.rfind("building", 0) == 0; });
  EXPECT_TRUE(opened.ok()) << opened.message();
  return built;
}

void write_schema(const fs::path& path, float hip_weight) {
  std::ofstream(path) << R"({"channels": [
      {"name": "left_foot_position", "kind": "bone_position", "bone": "@left_foot"},
      {"name": "right_foot_position", "kind": "bone_position", "bone": "@right_foot"},
      {"name": "hip_velocity", "kind": "root_velocity", "bone": "@hips", "weight": )"
                      << hip_weight << "}]}";
}

// A manifest's schema file used to be left out of the digest: after an edit
// of its weights, the crowd ran on the entry built with the old ones.
TEST(CrowdCacheDigest, EditingTheSchemaFileBuildsANewEntry) {
  const fs::path dir = test::make_temp_dir();
  const fs::path clip = test::test_source_dir().parent_path() / "host/crowd/data/cmu131/131_09.bvh";
  std::ofstream(dir / "m.json") << R"({"fps": 30, "schema": "schema.json", "clips": [{"file": ")" << clip.string()
                                << R"(", "tags": ["walk"]}]})";
  write_schema(dir / "schema.json", 1.0f);
  const fs::path cache = dir / "cache";
  EXPECT_TRUE(opened_by_building(dir / "m.json", cache));
  EXPECT_FALSE(opened_by_building(dir / "m.json", cache)) << "the second open reads the entry";
  write_schema(dir / "schema.json", 4.0f);
  EXPECT_TRUE(opened_by_building(dir / "m.json", cache)) << "the edited schema must not reuse the old entry";
}

}  // namespace
}  // namespace mmvk::crowd
