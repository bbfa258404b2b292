// Everything `mmvk crowd` is asked to do, as the command line parsed it: the
// crowd's settings (crowd_settings.hpp, shared with the stepped crowd and
// mmvk.Crowd) and what only the command has, its data, files and terminal.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>

#include "setup/crowd_settings.hpp"

namespace mmvk::crowd {

// --export-agents' default: the characters --bvh and --gltf write (or the
// whole crowd, when it is smaller).
inline constexpr std::uint32_t kDefaultExportAgents = 10;

struct CrowdOptions : CrowdSettings {
  std::optional<std::filesystem::path> data;  // a shipped set's name, .mmdb, manifest or BVH folder; none = the default set
  std::optional<std::filesystem::path> scenario;
  std::optional<std::filesystem::path> summary;
  std::optional<std::filesystem::path> html;
  // The displayed joint positions of the first trace_agents characters,
  // every tick (trace.hpp).
  std::optional<std::filesystem::path> trace;
  std::uint32_t trace_agents = 1;
  // The displayed poses of the first export_agents characters, every tick:
  // one BVH per character in `bvh`, one glTF binary `gltf` (pose_export.hpp).
  std::optional<std::filesystem::path> bvh;
  std::optional<std::filesystem::path> gltf;
  std::uint32_t export_agents = 0;  // 0: kDefaultExportAgents, or the crowd when smaller
  // Set by the command line, not by flags.
  std::filesystem::path executable;           // for the shipped data beside an installed binary
  std::filesystem::path cache_dir;            // empty: never cache
  bool progress = false;                      // draw the live progress line (stderr is a terminal)
};

}  // namespace mmvk::crowd
