// The database `mmvk crowd` animates: an .mmdb as it is, or a manifest or a
// folder of BVH built once and cached, or one of the motion sets shipped in
// host/crowd/data by name (--data cmu-walks). Without --data, the default
// set: the trimmed CMU subject 16 walks and runs (cmu-walk-run).
// A shipped set carries the crowd settings it was tuned with, in its
// manifest's "crowd" block (data_settings.hpp); each flag overrides its
// setting (bench/RESULTS.md, "The default data").
//
// A built database is cached as <cache dir>/crowd-<name>-<digest>.mmdb, where
// the digest covers the manifest, every BVH it names and the .mmdb format
// version, so an edited clip or a new format rebuilds it. The caller picks the
// cache dir (the command line: $XDG_CACHE_HOME/mmvk or ~/.cache/mmvk); a cache
// that cannot be written only costs a rebuild next time.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// A motion set shipped with mmvk, chosen by name with --data.
struct ShippedData {
  std::string_view name;         // the --data name, e.g. "cmu-walks"
  std::string_view folder;       // under host/crowd/data (installed: <prefix>/share/mmvk/crowd)
  std::string_view label;        // short, for the viewer's header: "CMU 131 walks"
  std::string_view description;  // what it holds, for --help and the README
  // What it can do, for --help without reading the data: the line
  // gait_capabilities() (mmvk/database/gait_coverage.hpp) gives for the built set,
  // which a test checks against the build.
  std::string_view capabilities;
};

// Every shipped set; the first is the default.
std::span<const ShippedData> shipped_data();
// The set named `name`, or nullptr.
const ShippedData* find_shipped_data(std::string_view name);

// Where a shipped set's manifest may be: beside an installed binary
// (<prefix>/share/mmvk/crowd/<folder>) and in the source tree the binary was
// built from. `executable` is the running program's path (may be empty).
std::vector<std::filesystem::path> shipped_manifest_candidates(const ShippedData& data,
                                                               const std::filesystem::path& executable);

// What --data names, resolved: a shipped set's manifest (a shipped name wins
// over a file of that name in the working directory: write ./cmu-walks for
// the file), or the path as given.
struct DataChoice {
  std::filesystem::path source;  // an .mmdb, a manifest or a folder of BVH
  std::string label;             // for messages: "the CMU subject 131 walks (cmu-walks)"
  std::string short_label;       // for the viewer's header
};
// `data` none: the default set. Error: a shipped set whose files are missing.
Result<DataChoice> choose_data(const std::optional<std::filesystem::path>& data,
                               const std::filesystem::path& executable);

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
