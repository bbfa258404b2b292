#include "output/trace.hpp"

#include <nlohmann/json.hpp>

#include "mmvk/common/file_io.hpp"
#include "mmvk/features/foot_contacts.hpp"

namespace mmvk::crowd {

namespace {

constexpr const char* kFormat = "mmvk crowd trace";
constexpr int kVersion = 1;

// Every trace file goes through here: one writer to swap for another.
Status write_output(const std::filesystem::path& path, std::string_view bytes) {
  return write_file_atomically(path, bytes);
}

nlohmann::ordered_json per_tick(std::span<const std::uint8_t> values, std::uint64_t ticks, std::uint32_t agents) {
  nlohmann::ordered_json rows = nlohmann::ordered_json::array();
  for (std::uint64_t t = 0; t < ticks; ++t) rows.push_back(values.subspan(t * agents, agents));
  return rows;
}

Result<std::vector<std::uint8_t>> read_per_tick(const nlohmann::json& sidecar, const char* key,
                                                const TraceLayout& layout, const std::string& where) {
  const auto found = sidecar.find(key);
  if (found == sidecar.end() || !found->is_array() || found->size() != layout.ticks) {
    return make_error(where + ": " + key + ": expected " + std::to_string(layout.ticks) + " rows");
  }
  std::vector<std::uint8_t> values;
  values.reserve(layout.ticks * layout.agents);
  for (const auto& row : *found) {
    if (!row.is_array() || row.size() != layout.agents) {
      return make_error(where + ": " + key + ": expected rows of " + std::to_string(layout.agents) + " values");
    }
    for (const auto& value : row) {
      if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 255) {
        return make_error(where + ": " + key + ": expected bit sets in [0, 255]");
      }
      values.push_back(value.get<std::uint8_t>());
    }
  }
  return values;
}

}  // namespace

std::filesystem::path trace_sidecar_path(const std::filesystem::path& trace) {
  return std::filesystem::path(trace.string() + ".json");
}

Result<TraceWriter> TraceWriter::create(const std::filesystem::path& path, const TraceLayout& layout,
                                        const Skeleton& skeleton, std::array<int, 2> contact_joints,
                                        std::uint32_t crowd_agents) {
  if (layout.agents == 0 || layout.agents > crowd_agents) {
    return make_error("--trace-agents " + std::to_string(layout.agents) + " must be in [1, " +
                      std::to_string(crowd_agents) + "], the characters in the crowd");
  }
  // In doubles first: a product that overflows 64 bits must not wrap under the cap.
  const double bytes = double(layout.ticks) * layout.agents * layout.joints * 12.0;
  if (bytes > double(kMaxTraceBytes)) {
    return make_error("--trace: " + std::to_string(layout.ticks) + " ticks x " + std::to_string(layout.agents) +
                      " agents x " + std::to_string(layout.joints) + " joints would take " +
                      std::to_string(std::uint64_t(bytes / double(1 << 20))) + " MiB, over the " +
                      std::to_string(kMaxTraceBytes >> 20) +
                      " MiB a trace may take; trace fewer characters (--trace-agents) or a shorter run");
  }
  for (const auto& file : {path, trace_sidecar_path(path)}) {
    if (Status writable = check_writable(file); !writable) return make_error("--trace: " + writable.message());
  }
  TraceWriter w;
  w.path_ = path;
  w.layout_ = layout;
  w.names_ = skeleton.names;
  w.parents_.assign(skeleton.parents.begin(), skeleton.parents.end());
  w.contact_joints_ = contact_joints;
  w.positions_.reserve(layout.position_bytes());
  w.contacts_.reserve(layout.ticks * layout.agents);
  w.locks_.reserve(layout.ticks * layout.agents);
  return w;
}

void TraceWriter::record(std::span<const glm::vec3> world, std::span<const std::uint8_t> contacts,
                         std::span<const std::uint8_t> locked) {
  if (recorded_ == layout_.ticks) return;
  const std::size_t joints = layout_.joints;
  for (std::size_t b = 0; b < layout_.agents; ++b) {
    for (std::size_t j = 0; j < joints; ++j) {
      const glm::vec3& p = world[b * joints + j];
      const float xyz[3] = {p.x, p.y, p.z};
      append_f32_le(positions_, xyz);
    }
    contacts_.push_back(contacts[b]);
    locks_.push_back(locked.empty() ? 0 : std::uint8_t((locked[2 * b] ? 1 : 0) | (locked[2 * b + 1] ? 2 : 0)));
  }
  ++recorded_;
}

Status TraceWriter::finish() const {
  MMVK_TRY(write_output(path_, positions_));
  nlohmann::ordered_json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["positions_file"] = path_.filename().string();
  j["dtype"] = "float32";
  j["byte_order"] = "little";
  j["shape"] = {recorded_, layout_.agents, layout_.joints, 3};
  j["units"] = "metres, world space, +Y up; row t is the pose after tick t, at (t + 1) / tick_rate_hz s";
  j["tick_rate_hz"] = layout_.tick_rate_hz;
  j["ticks"] = recorded_;
  j["agents"] = layout_.agents;
  j["joints"] = layout_.joints;
  j["joint_names"] = names_;
  j["parents"] = parents_;
  j["contact_joints"] = contact_joints_;
  j["contact_bits"] = {{"left", kContactLeft},          {"right", kContactRight},
                       {"left_heel", kContactLeftHeel}, {"left_toe", kContactLeftToe},
                       {"right_heel", kContactRightHeel}, {"right_toe", kContactRightToe}};
  j["contacts"] = per_tick(contacts_, recorded_, layout_.agents);
  j["foot_lock_bits"] = {{"left", 1}, {"right", 2}};
  j["foot_locks"] = per_tick(locks_, recorded_, layout_.agents);
  const std::string text = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
  return write_output(trace_sidecar_path(path_), text);
}

Result<Trace> read_trace(const std::filesystem::path& path) {
  const std::filesystem::path sidecar_path = trace_sidecar_path(path);
  const std::string where = sidecar_path.string();
  MMVK_ASSIGN_OR_RETURN(const std::string text, read_file(sidecar_path));
  const nlohmann::json sidecar = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (sidecar.is_discarded() || !sidecar.is_object()) return make_error(where + ": not valid JSON");
  // Found or null: json::value() would throw on a field of another type.
  const auto field = [&sidecar](const char* key) {
    const auto found = sidecar.find(key);
    return found == sidecar.end() ? nlohmann::json() : *found;
  };
  if (field("format") != kFormat || field("version") != kVersion) {
    return make_error(where + ": not a version " + std::to_string(kVersion) + " " + kFormat + " sidecar");
  }
  Trace trace;
  TraceLayout& layout = trace.layout;
  const nlohmann::json shape = field("shape");
  if (!shape.is_array() || shape.size() != 4 || !shape[0].is_number_unsigned() || !shape[1].is_number_unsigned() ||
      !shape[2].is_number_unsigned() || shape[3] != 3 || shape[1].get<std::uint64_t>() > UINT32_MAX ||
      shape[2].get<std::uint64_t>() > UINT32_MAX) {
    return make_error(where + ": shape: expected [ticks, agents, joints, 3]");
  }
  layout.ticks = shape[0].get<std::uint64_t>();
  layout.agents = shape[1].get<std::uint32_t>();
  layout.joints = shape[2].get<std::uint32_t>();
  const nlohmann::json rate = field("tick_rate_hz");
  if (!rate.is_number() || !(rate.get<double>() > 0.0)) return make_error(where + ": tick_rate_hz: expected a positive number");
  layout.tick_rate_hz = rate.get<double>();
  const nlohmann::json names = field("joint_names"), parents = field("parents");
  if (!names.is_array() || names.size() != layout.joints || !parents.is_array() || parents.size() != layout.joints) {
    return make_error(where + ": joint_names and parents: expected " + std::to_string(layout.joints) + " each");
  }
  for (std::size_t i = 0; i < layout.joints; ++i) {
    if (!names[i].is_string() || !parents[i].is_number_integer()) {
      return make_error(where + ": joint " + std::to_string(i) + ": expected a name and an integer parent");
    }
    trace.joint_names.push_back(names[i].get<std::string>());
    trace.parents.push_back(parents[i].get<int>());
  }
  const nlohmann::json contact_joints = field("contact_joints");
  if (!contact_joints.is_array() || contact_joints.size() != 2 || !contact_joints[0].is_number_integer() ||
      !contact_joints[1].is_number_integer()) {
    return make_error(where + ": contact_joints: expected [left, right]");
  }
  trace.contact_joints = {contact_joints[0].get<int>(), contact_joints[1].get<int>()};
  MMVK_ASSIGN_OR_RETURN(trace.contacts, read_per_tick(sidecar, "contacts", layout, where));
  MMVK_ASSIGN_OR_RETURN(trace.foot_locks, read_per_tick(sidecar, "foot_locks", layout, where));
  MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(path));
  if (bytes.size() != layout.position_bytes()) {
    return make_error(path.string() + ": " + std::to_string(bytes.size()) + " bytes, expected " +
                      std::to_string(layout.position_bytes()) + " for the sidecar's shape");
  }
  trace.positions.resize(bytes.size() / 4);
  decode_f32_le(bytes, trace.positions);
  return trace;
}

}  // namespace mmvk::crowd
