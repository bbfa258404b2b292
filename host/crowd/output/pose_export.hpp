// `mmvk crowd --bvh DIR --gltf FILE.glb --export-agents M`: the displayed
// poses of the first M characters recorded every tick (pose_recording.hpp)
// and written when the run ends, one BVH per character (bvh_export.hpp) and
// one glTF binary (gltf_export.hpp). Everything a run could fail on at its
// end is checked before it starts: the count against the crowd, the
// recording against its cap, the folder and files writable.
#pragma once

#include <optional>

#include "setup/crowd_options.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/common/status.hpp"
#include "output/pose_recording.hpp"

namespace mmvk::crowd {

// Before the database is opened, making and writing nothing: --bvh's
// folder and its files writable (a folder not there yet is made when the
// files are written, so a run that fails leaves none behind), --gltf named
// .glb and writable. Errors name the option.
Status check_pose_export_paths(const CrowdOptions& options);

// The characters exported from a crowd of `crowd_agents`: --export-agents,
// else kDefaultExportAgents or the crowd when smaller.
std::uint32_t export_count(const CrowdOptions& options, std::uint32_t crowd_agents);

class PoseExport {
 public:
  // Nothing when neither --bvh nor --gltf is given. Errors name
  // --export-agents (beyond `crowd_agents`) or the option whose output
  // would take the recording over its cap.
  static Result<std::optional<PoseExport>> open(const CrowdOptions& options, const AnimationData& animation,
                                                std::uint32_t crowd_agents, std::uint64_t ticks);
  // After each tick.
  Status record(const CrowdController& controller) { return recorder_.record(controller); }
  // Writes the files. Errors name the file.
  Status finish() const;

 private:
  PoseExport(const CrowdOptions& options, PoseRecorder recorder);

  std::optional<std::filesystem::path> bvh_, gltf_;
  PoseRecorder recorder_;
};

}  // namespace mmvk::crowd
