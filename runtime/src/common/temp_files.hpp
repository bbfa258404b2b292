// The temp files of the atomic writer (output_file.cpp): named after the
// target with the writer's PID, so that the temps of a writer killed
// mid-write (a full-size copy of a database or cache entry each) can be
// told from those of a live one and removed by the next writer there.
#pragma once

#include <filesystem>
#include <string>

namespace mmvk::detail {

// The folder a target lives in ("." for a bare name).
std::filesystem::path folder_of(const std::filesystem::path& target);

// "<target name>.tmp-<pid>-<12 hex digits>" in the target's folder, the
// digits random (or from `attempt` when no randomness is available).
std::filesystem::path temp_name(const std::filesystem::path& target, unsigned attempt);

// The PID in a temp_name's file name, or 0 when `name` is not one.
long temp_writer_pid(const std::string& name);

// Removes the regular files in `folder` named like temp_name's whose PID
// names no running process and that belong to this user; returns how many.
// Best effort: a folder that cannot be listed, or a file that cannot be
// removed, is left as it is.
std::size_t reap_stale_temps(const std::filesystem::path& folder);

}  // namespace mmvk::detail
