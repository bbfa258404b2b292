#include "animation_report.hpp"

#include <bit>
#include <cstdio>
#include <string>

#include "mmvk/common/file_io.hpp"
#include "cli_args.hpp"
#include "contact_report.hpp"

namespace mmvk::cli {

namespace {

const char* encoding_name(RotationEncoding encoding) {
  return encoding == RotationEncoding::Float32 ? "float32" : "quantized16";
}

}  // namespace

void print_animation(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) {
    std::printf("animation: none, features only (%s)\n", no_animation_explanation(database.no_animation_reason()).c_str());
    return;
  }
  std::printf("animation: %zu joints (%zu translated per frame), rotations %s; %zu bytes per frame in the file, "
              "%zu in memory (%s bytes in the file)\n",
              a->joint_count(), a->translated_joints.size(), encoding_name(a->encoding), a->bytes_per_frame_in_file(),
              a->bytes_per_frame_in_memory(),
              thousands(static_cast<unsigned long long>(a->bytes_per_frame_in_file()) * a->frame_count).c_str());
  print_contacts(database);
}

nlohmann::json animation_json(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) {
    return {{"present", false}, {"reason", no_animation_explanation(database.no_animation_reason())}};
  }
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
          {"contacts", contacts_json(database)}};
}

Status export_animation(const Database& database, const std::string& source, const std::filesystem::path& values,
                        const std::filesystem::path& sidecar) {
  const AnimationData* a = database.animation();
  if (a == nullptr) return missing_animation_error("mmvk export --animation", database.no_animation_reason());
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
      "facing = (sin yaw, 0, cos yaw)); untranslated joints use rest_offset; contacts: bit 0 left foot planted, bit 1 right, bit 2 left heel, "
      "bit 3 left toe, bit 4 right heel, bit 5 right toe (a foot is planted when its heel or toe is)";
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
