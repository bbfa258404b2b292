#include "output/gltf_export.hpp"

#include <algorithm>
#include <array>
#include <utility>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "mmvk/common/file_io.hpp"

namespace mmvk::crowd {

namespace {

using Json = nlohmann::ordered_json;

constexpr int kFloat = 5126;  // glTF's componentType for float32

// Every export file goes through here: the project's one writer.
Status write_output(const std::filesystem::path& path, std::string_view bytes) {
  return write_file_atomically(path, bytes);
}

// The binary chunk and the JSON that describes it, built together: each
// accessor gets a buffer view of its own, 4-byte aligned (float data only).
class GltfBuilder {
 public:
  // Appends `values` as an accessor of `count` elements of `type`
  // ("SCALAR", "VEC3", ...); returns its index.
  int accessor(const std::vector<float>& values, std::size_t count, const char* type, bool with_bounds = false) {
    Json view{{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", values.size() * 4}};
    append_f32_le(bin_, values);
    views_.push_back(view);
    Json a{{"bufferView", views_.size() - 1}, {"componentType", kFloat}, {"count", count}, {"type", type}};
    if (with_bounds) {
      const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
      a["min"] = {*lo};
      a["max"] = {*hi};
    }
    accessors_.push_back(a);
    return int(accessors_.size() - 1);
  }
  Json& json() { return json_; }
  std::string glb();

 private:
  Json json_ = Json::object();
  Json views_ = Json::array(), accessors_ = Json::array();
  std::string bin_;
};

void append_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(char((v >> (8 * i)) & 0xFF));
}

std::string GltfBuilder::glb() {
  json_["buffers"] = Json::array({Json{{"byteLength", bin_.size()}}});
  json_["bufferViews"] = views_;
  json_["accessors"] = accessors_;
  std::string text = json_.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  text.append((4 - text.size() % 4) % 4, ' ');
  std::string bin = std::move(bin_);
  bin.append((4 - bin.size() % 4) % 4, '\0');
  std::string out;
  append_u32(out, 0x46546C67);  // "glTF"
  append_u32(out, 2);
  append_u32(out, std::uint32_t(12 + 8 + text.size() + 8 + bin.size()));
  append_u32(out, std::uint32_t(text.size()));
  append_u32(out, 0x4E4F534A);  // "JSON"
  out += text;
  append_u32(out, std::uint32_t(bin.size()));
  append_u32(out, 0x004E4942);  // "BIN\0"
  out += bin;
  return out;
}

// One character's animated values: a vec3 or a quaternion per sample.
std::vector<float> vec3_track(const PoseRecording& rec, std::uint32_t agent, std::size_t joint) {
  std::vector<float> out;
  out.reserve(rec.ticks * 3);
  for (std::uint64_t t = 0; t < rec.ticks; ++t) {
    const glm::vec3 v = joint == SIZE_MAX ? rec.root_positions[t * rec.agents + agent] : rec.translation(t, agent, joint);
    out.insert(out.end(), {v.x, v.y, v.z});
  }
  return out;
}

std::vector<float> rotation_track(const PoseRecording& rec, std::uint32_t agent, std::size_t joint) {
  std::vector<float> out;
  out.reserve(rec.ticks * 4);
  glm::quat previous(1.0f, 0.0f, 0.0f, 0.0f);
  for (std::uint64_t t = 0; t < rec.ticks; ++t) {
    glm::quat q = joint == SIZE_MAX ? glm::angleAxis(rec.root_yaws[t * rec.agents + agent], glm::vec3(0.0f, 1.0f, 0.0f))
                                    : rec.rotation(t, agent, joint);
    q = glm::normalize(q);
    if (glm::dot(q, previous) < 0.0f) q = -q;  // the short arc from the sample before
    previous = q;
    out.insert(out.end(), {q.x, q.y, q.z, q.w});
  }
  return out;
}

// The rest pose's inverse bind matrices, [joints] column-major 4x4: every
// rotation the identity, so each is a translation by minus the joint's
// position in the agent node's space.
std::vector<float> inverse_bind_matrices(const PoseRecording& rec) {
  std::vector<glm::vec3> position(rec.joints());
  std::vector<float> out;
  for (std::size_t j = 0; j < rec.joints(); ++j) {
    const int parent = rec.skeleton.parents[j];
    position[j] = (parent < 0 ? glm::vec3(0.0f) : position[std::size_t(parent)]) + rec.translation(0, 0, j);
    const glm::vec3 p = -position[j];
    out.insert(out.end(), {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, p.x, p.y, p.z, 1});
  }
  return out;
}

Json vec_json(const float* v, int n) {
  Json out = Json::array();
  for (int i = 0; i < n; ++i) out.push_back(v[i]);
  return out;
}

// The nodes of one character (its agent node first, then its joints) and
// the animation's channels for them.
void add_agent(GltfBuilder& b, const PoseRecording& rec, std::uint32_t agent, int times, int bind, Json& nodes,
               Json& samplers, Json& channels) {
  const int base = int(nodes.size());
  const std::size_t joints = rec.joints();
  auto animate = [&](int node, const char* path, const std::vector<float>& values, const char* type) {
    const int output = b.accessor(values, rec.ticks, type);
    samplers.push_back(Json{{"input", times}, {"interpolation", "LINEAR"}, {"output", output}});
    channels.push_back(Json{{"sampler", samplers.size() - 1}, {"target", {{"node", node}, {"path", path}}}});
    nodes[std::size_t(node)][path] = vec_json(values.data(), type[3] == '3' ? 3 : 4);
  };
  char name[32];
  std::snprintf(name, sizeof(name), "agent_%04u", agent);
  nodes.push_back(Json{{"name", name}});
  Json skin_joints = Json::array();
  for (std::size_t j = 0; j < joints; ++j) {
    nodes.push_back(Json{{"name", rec.skeleton.names[j]}});
    const int parent = rec.skeleton.parents[j];
    Json& parent_node = nodes[std::size_t(parent < 0 ? base : base + 1 + parent)];
    parent_node["children"].push_back(base + 1 + int(j));
    skin_joints.push_back(base + 1 + int(j));
  }
  animate(base, "translation", vec3_track(rec, agent, SIZE_MAX), "VEC3");
  animate(base, "rotation", rotation_track(rec, agent, SIZE_MAX), "VEC4");
  for (std::size_t j = 0; j < joints; ++j) {
    const glm::vec3 rest = rec.translation(0, agent, j);
    nodes[std::size_t(base + 1) + j]["translation"] = {rest.x, rest.y, rest.z};
    animate(base + 1 + int(j), "rotation", rotation_track(rec, agent, j), "VEC4");
  }
  for (const std::uint32_t j : rec.translated_joints) {
    animate(base + 1 + int(j), "translation", vec3_track(rec, agent, j), "VEC3");
  }
  b.json()["skins"].push_back(
      Json{{"name", name}, {"inverseBindMatrices", bind}, {"skeleton", base}, {"joints", skin_joints}});
}

}  // namespace

Result<std::string> glb_bytes(const PoseRecording& rec) {
  if (rec.ticks == 0) return make_error("no poses recorded: step the crowd first");
  GltfBuilder b;
  b.json()["asset"] = Json{{"version", "2.0"}, {"generator", "mmvk crowd"}};
  std::vector<float> time(rec.ticks);
  for (std::uint64_t t = 0; t < rec.ticks; ++t) time[t] = float(double(t) / rec.tick_rate_hz);
  const int times = b.accessor(time, rec.ticks, "SCALAR", true);
  const int bind = b.accessor(inverse_bind_matrices(rec), rec.joints(), "MAT4");
  Json nodes = Json::array(), samplers = Json::array(), channels = Json::array(), roots = Json::array();
  b.json()["skins"] = Json::array();
  for (std::uint32_t agent = 0; agent < rec.agents; ++agent) {
    roots.push_back(nodes.size());
    add_agent(b, rec, agent, times, bind, nodes, samplers, channels);
  }
  b.json()["scene"] = 0;
  b.json()["scenes"] = Json::array({Json{{"name", "crowd"}, {"nodes", roots}}});
  b.json()["nodes"] = nodes;
  b.json()["animations"] = Json::array({Json{{"name", "crowd"}, {"samplers", samplers}, {"channels", channels}}});
  return b.glb();
}

Status check_gltf_path(const std::filesystem::path& path, const std::string& option) {
  if (path.extension() != ".glb") {
    return make_error(option + " " + path.string() + ": the export is a binary glTF; name it .glb");
  }
  if (Status writable = check_writable(path); !writable) return make_error(option + ": " + writable.message());
  return {};
}

Status write_gltf(const PoseRecording& rec, const std::filesystem::path& path) {
  MMVK_ASSIGN_OR_RETURN(const std::string bytes, glb_bytes(rec));
  return write_output(path, bytes);
}

}  // namespace mmvk::crowd
