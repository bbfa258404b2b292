// A scene file read by assimp in a child process. assimp 5.2 crashes, aborts
// or allocates without bound on some damaged files (a COLLADA index list
// with a stray letter grows to gigabytes); in a child process that is an
// error for the caller, not the end of the build, the Python interpreter or
// the host application that embeds mmvk.
#pragma once

#include <filesystem>
#include <functional>

#include "mmvk/import/scene_import.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk::detail {

using SceneReader = std::function<Result<SceneImport>(const std::filesystem::path&, const SceneImportOptions&)>;

// Runs `read(path, options)` in a forked child within options.timeout_seconds
// and options.memory_budget_bytes (beyond what the process already maps),
// and returns its result, or an error naming the file when the child crashes,
// runs out of time or memory, or cannot be started.
Result<SceneImport> read_scene_in_child(const std::filesystem::path& path, const SceneImportOptions& options,
                                        const SceneReader& read);

}  // namespace mmvk::detail
