#include "animation_report.hpp"

#include <cstdio>
#include <string>

#include "cli_args.hpp"

namespace mmvk::cli {

namespace {

const char* encoding_name(RotationEncoding encoding) {
  return encoding == RotationEncoding::Float32 ? "float32" : "quantized16";
}

// Frames with each foot in contact.
std::pair<std::uint64_t, std::uint64_t> contact_frames(const AnimationData& a) {
  std::uint64_t left = 0;
  std::uint64_t right = 0;
  for (std::uint8_t c : a.contacts) {
    left += (c & kContactLeft) ? 1 : 0;
    right += (c & kContactRight) ? 1 : 0;
  }
  return {left, right};
}

std::string joint_name(const AnimationData& a, int joint) {
  return joint < 0 ? std::string("none") : a.skeleton.names[static_cast<std::size_t>(joint)];
}

}  // namespace

void print_animation(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) {
    std::printf("animation: none (features only; rebuild without --no-animation to add poses)\n");
    return;
  }
  const auto [left, right] = contact_frames(*a);
  const double frames = a->frame_count > 0 ? double(a->frame_count) : 1.0;
  std::printf("animation: %zu joints (%zu translated per frame), rotations %s; %zu bytes per frame in the file, "
              "%zu in memory (%s bytes in the file)\n",
              a->joint_count(), a->translated_joints.size(), encoding_name(a->encoding), a->bytes_per_frame_in_file(),
              a->bytes_per_frame_in_memory(),
              thousands(static_cast<unsigned long long>(a->bytes_per_frame_in_file()) * a->frame_count).c_str());
  std::printf("contacts: %s %.0f%% of frames, %s %.0f%% (height < %g m, speed < %g m/s)\n",
              joint_name(*a, a->contact_joints[0]).c_str(), 100.0 * double(left) / frames,
              joint_name(*a, a->contact_joints[1]).c_str(), 100.0 * double(right) / frames,
              double(a->contact_params.max_height), double(a->contact_params.max_speed));
}

nlohmann::json animation_json(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) return {{"present", false}};
  const auto [left, right] = contact_frames(*a);
  nlohmann::json joints = nlohmann::json::array();
  for (std::size_t j = 0; j < a->joint_count(); ++j) {
    const glm::vec3& r = a->skeleton.rest_offsets[j];
    joints.push_back({{"name", a->skeleton.names[j]},
                      {"parent", a->skeleton.parents[j]},
                      {"rest_offset", {r.x, r.y, r.z}},
                      {"mirror", a->mirror_pairs[j]}});
  }
  return {{"present", true},
          {"joints", joints},
          {"translated_joints", a->translated_joints},
          {"rotation_encoding", encoding_name(a->encoding)},
          {"bytes_per_frame_file", a->bytes_per_frame_in_file()},
          {"bytes_per_frame_memory", a->bytes_per_frame_in_memory()},
          {"contact_joints", {joint_name(*a, a->contact_joints[0]), joint_name(*a, a->contact_joints[1])}},
          {"contact_max_height", a->contact_params.max_height},
          {"contact_max_speed", a->contact_params.max_speed},
          {"contact_frames", {left, right}}};
}

}  // namespace mmvk::cli
