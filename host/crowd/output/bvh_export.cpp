#include "output/bvh_export.hpp"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <system_error>

#include <unistd.h>

#include <glm/gtc/quaternion.hpp>

#include "mmvk/common/file_io.hpp"

namespace mmvk::crowd {

namespace {

constexpr float kCentimetresPerMetre = 100.0f;

// Every export file goes through here: the project's one writer.
Status write_output(const std::filesystem::path& path, std::string_view bytes) {
  return write_file_atomically(path, bytes);
}

// `dir` as a folder: made when missing (its parent must exist).
Status make_folder(const std::filesystem::path& dir) {
  std::error_code ec;
  if (std::filesystem::create_directory(dir, ec) || std::filesystem::is_directory(dir)) return {};
  return make_error(dir.string() + ": cannot make the folder" + (ec ? ": " + ec.message() : std::string()));
}

// The joints in the file's order (depth first, children in skeleton order)
// and each joint's children: the MOTION lines follow the hierarchy's order,
// which need not be the skeleton's.
struct Hierarchy {
  std::vector<std::vector<std::size_t>> children;
  std::vector<std::size_t> order;
  std::vector<bool> positioned;  // position channels: a root or a translated joint
};

Hierarchy hierarchy_of(const PoseRecording& rec) {
  Hierarchy h;
  const std::size_t joints = rec.joints();
  h.children.resize(joints);
  h.positioned.assign(joints, false);
  std::vector<std::size_t> roots;
  for (std::size_t j = 0; j < joints; ++j) {
    const int parent = rec.skeleton.parents[j];
    if (parent < 0) {
      roots.push_back(j);
      h.positioned[j] = true;
    } else {
      h.children[std::size_t(parent)].push_back(j);
    }
  }
  for (const std::uint32_t j : rec.translated_joints) h.positioned[j] = true;
  std::vector<std::size_t> stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const std::size_t j = stack.back();
    stack.pop_back();
    h.order.push_back(j);
    stack.insert(stack.end(), h.children[j].rbegin(), h.children[j].rend());
  }
  return h;
}

void append(std::string& out, const char* format, double a, double b, double c) {
  char text[128];
  const int n = std::snprintf(text, sizeof(text), format, a, b, c);
  out.append(text, std::size_t(n));
}

void append_joint(std::string& out, const PoseRecording& rec, const Hierarchy& h, std::size_t j, int depth) {
  const std::string indent(std::size_t(depth) * 2, ' ');
  const glm::vec3 offset = rec.skeleton.rest_offsets[j] * kCentimetresPerMetre;
  out += indent + (rec.skeleton.parents[j] < 0 ? "ROOT " : "JOINT ") + rec.skeleton.names[j] + "\n" + indent + "{\n";
  append(out, (indent + "  OFFSET %.6f %.6f %.6f\n").c_str(), offset.x, offset.y, offset.z);
  out += indent + (h.positioned[j] ? "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                                   : "  CHANNELS 3 Zrotation Xrotation Yrotation\n");
  for (const std::size_t child : h.children[j]) append_joint(out, rec, h, child, depth + 1);
  if (h.children[j].empty()) {
    const glm::vec3 tip = glm::length(offset) > 0.0f ? 0.5f * offset : glm::vec3(0.0f, 2.0f, 0.0f);
    out += indent + "  End Site\n" + indent + "  {\n";
    append(out, (indent + "    OFFSET %.6f %.6f %.6f\n").c_str(), tip.x, tip.y, tip.z);
    out += indent + "  }\n";
  }
  out += indent + "}\n";
}

// Degrees (z, x, y) with R = Rz(z) * Rx(x) * Ry(y): from the matrix's
// entries m(2,1) = sin x, m(0,1) = -sin z cos x, m(1,1) = cos z cos x,
// m(2,0) = -cos x sin y, m(2,2) = cos x cos y (glm indexes [column][row]).
glm::vec3 zxy_degrees(const glm::quat& q) {
  const glm::mat3 m = glm::mat3_cast(glm::normalize(q));
  const float x = std::asin(std::clamp(m[1][2], -1.0f, 1.0f));
  const float z = std::atan2(-m[1][0], m[1][1]);
  const float y = std::atan2(-m[0][2], m[2][2]);
  return glm::degrees(glm::vec3(z, x, y));
}

void append_frame(std::string& out, const PoseRecording& rec, const Hierarchy& h, std::uint64_t t,
                  std::uint32_t agent) {
  const std::size_t sample = t * rec.agents + agent;
  const glm::vec3 root = rec.root_positions[sample];
  const glm::quat yaw = glm::angleAxis(rec.root_yaws[sample], glm::vec3(0.0f, 1.0f, 0.0f));
  for (const std::size_t j : h.order) {
    glm::vec3 position = rec.translation(t, agent, j);
    glm::quat rotation = rec.rotation(t, agent, j);
    if (rec.skeleton.parents[j] < 0) {
      position = root + yaw * position;
      rotation = yaw * rotation;
    }
    if (h.positioned[j]) {
      position *= kCentimetresPerMetre;
      append(out, "%.6f %.6f %.6f ", position.x, position.y, position.z);
    }
    const glm::vec3 angles = zxy_degrees(rotation);
    append(out, "%.6f %.6f %.6f ", angles.x, angles.y, angles.z);
  }
  out.back() = '\n';
}

}  // namespace

std::vector<std::filesystem::path> bvh_paths(const std::filesystem::path& dir, std::uint32_t agents) {
  const int width = agents > 10000 ? int(std::to_string(agents - 1).size()) : 4;
  std::vector<std::filesystem::path> paths;
  paths.reserve(agents);
  for (std::uint32_t b = 0; b < agents; ++b) {
    char name[32];
    std::snprintf(name, sizeof(name), "agent_%0*u.bvh", width, b);
    paths.push_back(dir / name);
  }
  return paths;
}

Status check_bvh_folder(const std::filesystem::path& dir, std::uint32_t agents, const std::string& option) {
  namespace fs = std::filesystem;
  if (dir.empty()) return make_error(option + ": an empty path");
  std::error_code ec;
  if (fs::is_directory(dir, ec)) {
    for (const fs::path& file : bvh_paths(dir, agents)) {
      if (Status writable = check_writable(file); !writable) return make_error(option + ": " + writable.message());
    }
    return {};
  }
  const std::string named = option + " " + dir.string();
  if (fs::exists(fs::symlink_status(dir, ec))) {
    return make_error(named + (fs::is_symlink(fs::symlink_status(dir, ec)) && !fs::exists(dir, ec)
                                   ? ": a link to nothing"
                                   : ": not a folder"));
  }
  // Made when the files are written, as mkdir makes it: in a folder that
  // exists and can be written (the files in a new folder of ours can be).
  const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
  if (!fs::is_directory(parent, ec)) {
    return make_error(named + ": cannot make the folder there: " + parent.string() +
                      (fs::exists(parent, ec) ? " is not a folder" : " does not exist"));
  }
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    return make_error(named + ": cannot make the folder in " + parent.string() + ": " +
                      std::generic_category().message(errno));
  }
  return {};
}

Result<std::string> bvh_text(const PoseRecording& rec, std::uint32_t agent) {
  if (rec.ticks == 0) return make_error("no poses recorded: step the crowd first");
  const Hierarchy h = hierarchy_of(rec);
  if (h.order.size() != rec.joints()) return make_error("the skeleton's joints are not a tree");
  std::string out = "HIERARCHY\n";
  for (const std::size_t j : h.order) {
    if (rec.skeleton.parents[j] < 0) append_joint(out, rec, h, j, 0);
  }
  out += "MOTION\nFrames: " + std::to_string(rec.ticks) + "\n";
  append(out, "Frame Time: %.9f\n", 1.0 / rec.tick_rate_hz, 0.0, 0.0);
  for (std::uint64_t t = 0; t < rec.ticks; ++t) append_frame(out, rec, h, t, agent);
  return out;
}

Status write_bvh_files(const PoseRecording& rec, const std::filesystem::path& dir) {
  const std::vector<std::filesystem::path> paths = bvh_paths(dir, rec.agents);
  for (std::uint32_t b = 0; b < rec.agents; ++b) {
    MMVK_ASSIGN_OR_RETURN(const std::string text, bvh_text(rec, b));
    // The folder only once there is a file to put in it, so a run that
    // fails before (or a text that cannot be made) leaves nothing behind.
    if (b == 0) MMVK_TRY(make_folder(dir));
    if (Status written = write_output(paths[b], text); !written) return written;
  }
  return {};
}

}  // namespace mmvk::crowd
