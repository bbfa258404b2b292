// The database `mmvk crowd` animates: an .mmdb as it is, or a manifest or a
// folder of BVH built once and cached. Without --data, the trimmed CMU
// subject 131 walks shipped in host/crowd/data/cmu131.
//
// A built database is cached as <cache dir>/crowd-<name>-<digest>.mmdb, where
// the digest covers the manifest, every BVH it names and the .mmdb format
// version, so an edited clip or a new format rebuilds it. The caller picks the
// cache dir (the command line: $XDG_CACHE_HOME/mmvk or ~/.cache/mmvk); a cache
// that cannot be written only costs a rebuild next time.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "mmvk/database.hpp"
#include "mmvk/status.hpp"

namespace mmvk::crowd {

// Where the shipped manifest may be: beside an installed binary
// (<prefix>/share/mmvk/crowd/cmu131) and in the source tree the binary was
// built from. `executable` is the running program's path (may be empty).
std::vector<std::filesystem::path> default_manifest_candidates(const std::filesystem::path& executable);

struct OpenedDatabase {
  Database database;
  std::filesystem::path path;  // the .mmdb read or written (empty when not cached)
  bool built = false;          // built from BVH in this run
};

// `source`: an .mmdb file, a manifest JSON or a folder of BVH files.
// `say` receives one-line notes for the user (building, cached at, cache not
// writable).
Result<OpenedDatabase> open_database(const std::filesystem::path& source, const std::filesystem::path& cache_dir,
                                     const std::function<void(const std::string&)>& say);

}  // namespace mmvk::crowd
