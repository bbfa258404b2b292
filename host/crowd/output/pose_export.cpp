#include "output/pose_export.hpp"

#include <algorithm>
#include <utility>

#include "output/bvh_export.hpp"
#include "output/gltf_export.hpp"

namespace mmvk::crowd {

std::uint32_t export_count(const CrowdOptions& options, std::uint32_t crowd_agents) {
  return options.export_agents > 0 ? options.export_agents : std::min(kDefaultExportAgents, crowd_agents);
}

Status check_pose_export_paths(const CrowdOptions& options) {
  // The files of the largest count the run may take (the crowd is not known yet).
  const std::uint32_t count = options.export_agents > 0 ? options.export_agents : kDefaultExportAgents;
  if (options.bvh) MMVK_TRY(check_bvh_folder(*options.bvh, count, "--bvh"));
  if (options.gltf) MMVK_TRY(check_gltf_path(*options.gltf, "--gltf"));
  return {};
}

PoseExport::PoseExport(const CrowdOptions& options, PoseRecorder recorder)
    : bvh_(options.bvh), gltf_(options.gltf), recorder_(std::move(recorder)) {}

Result<std::optional<PoseExport>> PoseExport::open(const CrowdOptions& options, const AnimationData& animation,
                                                   std::uint32_t crowd_agents, std::uint64_t ticks) {
  if (!options.bvh && !options.gltf) return std::optional<PoseExport>();
  const std::string outputs = options.bvh && options.gltf ? "--bvh and --gltf" : options.bvh ? "--bvh" : "--gltf";
  MMVK_ASSIGN_OR_RETURN(PoseRecorder recorder, PoseRecorder::create(animation, export_count(options, crowd_agents), crowd_agents,
                                                                    options.rate_hz, ticks, "--export-agents", outputs));
  return std::optional<PoseExport>(PoseExport(options, std::move(recorder)));
}

Status PoseExport::finish() const {
  if (bvh_) MMVK_TRY(write_bvh_files(recorder_.recording(), *bvh_));
  if (gltf_) MMVK_TRY(write_gltf(recorder_.recording(), *gltf_));
  return {};
}

}  // namespace mmvk::crowd
