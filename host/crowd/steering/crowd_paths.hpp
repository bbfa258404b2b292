// The crowd's paths, checked before the database is opened or a tick runs:
// every output (--summary, --html, --trace and its sidecar, --gltf, --bvh's
// folder) writable, and
// none of them the same file as an input (the data, the BVH and sidecars
// its manifest or folder names, --scenario) or as another output. Before this check the crowd found a bad
// output path only after the simulation, and `--html c.mmdb --data c.mmdb`
// replaced the database with the page.
#pragma once

#include <vector>

#include "setup/crowd_options.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::crowd {

// The run's paths as check_command_paths takes them, named by option.
// `data_source`: the .mmdb, manifest or folder the run reads (choose_data's
// source: --data, a shipped set's manifest or the default one).
std::vector<NamedPath> crowd_paths(const CrowdOptions& options, const std::filesystem::path& data_source);
Status check_crowd_paths(const CrowdOptions& options, const std::filesystem::path& data_source);
// The same check with the database the run opened (`database`: the cache
// entry it read or built, or the --data .mmdb) as one more input, once its
// name is known (after the build, before the first tick): `--html` naming
// the cache entry would have replaced the entry with the page. Nothing when
// `database` is empty (not cached).
Status check_crowd_paths_with_database(const CrowdOptions& options, const std::filesystem::path& data_source,
                                       const std::filesystem::path& database);

}  // namespace mmvk::crowd
