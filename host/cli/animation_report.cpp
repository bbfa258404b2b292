#include "animation_report.hpp"

#include <bit>
#include <cstdio>
#include <string>

#include "mmvk/file_io.hpp"
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
  std::printf("contacts: %s %.0f%% of frames, %s %.0f%% (height < %s%g m, speed < %g m/s)\n",
              joint_name(*a, a->contact_joints[0]).c_str(), 100.0 * double(left) / frames,
              joint_name(*a, a->contact_joints[1]).c_str(), 100.0 * double(right) / frames,
              a->contact_params.height_above_clip_floor ? "clip floor + " : "", double(a->contact_params.max_height),
              double(a->contact_params.max_speed));
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
          {"contact_height_above_clip_floor", a->contact_params.height_above_clip_floor},
          {"contact_floor_percentile", a->contact_params.floor_percentile},
          {"contact_max_speed", a->contact_params.max_speed},
          {"contact_frames", {left, right}}};
}

Status export_animation(const Database& database, const std::string& source, const std::filesystem::path& values,
                        const std::filesystem::path& sidecar) {
  const AnimationData* a = database.animation();
  if (a == nullptr) return missing_animation_error("mmvk export --animation");
  const std::size_t joints = a->joint_count();
  const std::size_t translated = a->translated_joints.size();
  // Columns: rotations (x, y, z, w per joint), translations (x, y, z per
  // translated joint), root x, root z, root yaw, contact bits.
  const std::size_t columns = joints * 4 + translated * 3 + 4;
  std::string bytes;
  bytes.reserve(std::size_t{a->frame_count} * columns * 4);
  auto put = [&](float v) {
    const std::uint32_t bits = std::bit_cast<std::uint32_t>(v);
    for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<char>((bits >> (8 * b)) & 0xFF));
  };
  for (std::uint32_t f = 0; f < a->frame_count; ++f) {
    for (std::size_t j = 0; j < joints; ++j) {
      const glm::quat& q = a->local_rotations[f * joints + j];
      put(q.x);
      put(q.y);
      put(q.z);
      put(q.w);
    }
    for (std::size_t t = 0; t < translated; ++t) {
      const glm::vec3& v = a->local_translations[f * translated + t];
      put(v.x);
      put(v.y);
      put(v.z);
    }
    put(a->root_positions[f].x);
    put(a->root_positions[f].z);
    put(a->root_yaws[f]);
    put(float(a->contacts[f]));
  }
  nlohmann::json names = nlohmann::json::array();
  for (std::size_t j = 0; j < joints; ++j) {
    for (const char* c : {"x", "y", "z", "w"}) names.push_back("rotation." + a->skeleton.names[j] + "." + c);
  }
  for (std::uint32_t j : a->translated_joints) {
    for (const char* c : {"x", "y", "z"}) names.push_back("translation." + a->skeleton.names[j] + "." + c);
  }
  for (const char* c : {"root.x", "root.z", "root.yaw", "contacts"}) names.push_back(c);
  nlohmann::json out = animation_json(database);
  out["format"] = "float32 little-endian, row-major [frames x columns], one row per database frame";
  out["values"] = values.filename().string();
  out["source"] = source;
  out["frames"] = a->frame_count;
  out["fps"] = database.fps();
  out["columns"] = names;
  out["conventions"] =
      "metres, radians, Y up; rotations are local quaternions (x, y, z, w) relative to the parent, except that "
      "joints above the hips are the identity and the hips (and any joint without a parent) are relative to the "
      "character root; root.x/root.z/root.yaw place the character root in its clip's world (yaw 0 faces +Z, "
      "facing = (sin yaw, 0, cos yaw)); untranslated joints use rest_offset; contacts: bit 0 left, bit 1 right";
  out["clips"] = nlohmann::json::array();
  for (const Clip& clip : database.clips()) {
    out["clips"].push_back({{"name", clip.name}, {"first_frame", clip.first_frame}, {"frame_count", clip.frame_count},
                            {"loop", clip.loop}, {"mirrored", clip.mirrored}});
  }
  // The sidecar's text exists before any file is written; names with
  // invalid UTF-8 are replaced (U+FFFD), never thrown.
  const std::string sidecar_text = out.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  MMVK_TRY(write_file_atomically(values, bytes));
  return write_file_atomically(sidecar, sidecar_text);
}

}  // namespace mmvk::cli
