#include "output/pose_recording.hpp"

#include <algorithm>

namespace mmvk::crowd {

std::uint64_t PoseRecording::bytes_per_tick() const {
  return std::uint64_t(agents) * (sizeof(glm::vec3) + sizeof(float) + joints() * sizeof(glm::quat) +
                                  translated_joints.size() * sizeof(glm::vec3));
}

glm::vec3 PoseRecording::translation(std::uint64_t tick, std::uint32_t agent, std::size_t j) const {
  const auto found = std::lower_bound(translated_joints.begin(), translated_joints.end(), std::uint32_t(j));
  if (found == translated_joints.end() || *found != j) return skeleton.rest_offsets[j];
  const std::size_t k = std::size_t(found - translated_joints.begin());
  return translations[(tick * agents + agent) * translated_joints.size() + k];
}

Result<PoseRecorder> PoseRecorder::create(const AnimationData& animation, std::uint32_t agents,
                                          std::uint32_t crowd_agents, double tick_rate_hz, std::uint64_t ticks,
                                          const std::string& count_option, const std::string& size_option) {
  if (agents == 0 || agents > crowd_agents) {
    return make_error(count_option + " " + std::to_string(agents) + " must be in [1, " + std::to_string(crowd_agents) +
                      "], the characters in the crowd");
  }
  PoseRecorder r;
  r.count_option_ = count_option;
  r.size_option_ = size_option;
  PoseRecording& rec = r.recording_;
  rec.skeleton = animation.skeleton;
  rec.translated_joints = animation.translated_joints;
  rec.tick_rate_hz = tick_rate_hz;
  rec.agents = agents;
  MMVK_TRY(r.check_room(ticks));
  const std::uint64_t samples = ticks * agents;
  rec.root_positions.reserve(samples);
  rec.root_yaws.reserve(samples);
  rec.rotations.reserve(samples * rec.joints());
  rec.translations.reserve(samples * rec.translated_joints.size());
  return r;
}

Status PoseRecorder::check_room(std::uint64_t more) const {
  // In doubles: a product that overflows 64 bits must not wrap under the cap.
  const double bytes = double(recording_.ticks + more) * double(recording_.bytes_per_tick());
  if (bytes <= double(kMaxPoseRecordingBytes)) return {};
  return make_error(size_option_ + ": " + std::to_string(recording_.ticks + more) + " ticks x " +
                    std::to_string(recording_.agents) + " characters x " + std::to_string(recording_.joints()) +
                    " joints would take " + std::to_string(std::uint64_t(bytes / double(1 << 20))) +
                    " MiB of poses, over the " + std::to_string(kMaxPoseRecordingBytes >> 20) +
                    " MiB an export may hold; export fewer characters (" + count_option_ + ") or a shorter run");
}

Status PoseRecorder::record(const CrowdController& controller) {
  MMVK_TRY(check_room(1));
  PoseRecording& rec = recording_;
  const std::size_t joints = rec.joints();
  const auto rotations = controller.local_rotations();
  const auto translations = controller.local_translations();
  for (std::uint32_t b = 0; b < rec.agents; ++b) {
    rec.root_positions.push_back(controller.root_positions()[b]);
    rec.root_yaws.push_back(controller.root_yaws()[b]);
    rec.rotations.insert(rec.rotations.end(), rotations.begin() + std::ptrdiff_t(b * joints),
                         rotations.begin() + std::ptrdiff_t((b + 1) * joints));
    for (const std::uint32_t j : rec.translated_joints) rec.translations.push_back(translations[b * joints + j]);
  }
  ++rec.ticks;
  return {};
}

}  // namespace mmvk::crowd
