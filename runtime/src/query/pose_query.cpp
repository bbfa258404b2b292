#include "mmvk/query/pose_query.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <glm/geometric.hpp>

#include "common/json_parse.hpp"
#include "database/cost_bound.hpp"
#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/input_text.hpp"

namespace mmvk {

namespace {

using Json = nlohmann::json;

Result<glm::vec3> read_vec3(const Json& value, const std::string& where) {
  if (!value.is_array() || value.size() != 3) return make_error(where + ": expected [x, y, z]");
  glm::vec3 out(0.0f);
  for (int i = 0; i < 3; ++i) {
    MMVK_ASSIGN_OR_RETURN(out[i], detail::json_float(value[static_cast<std::size_t>(i)],
                                                     where + "[" + std::to_string(i) + "]"));
  }
  return out;
}

Result<PoseTarget> read_target(const Json& object, const std::string& where) {
  if (!object.is_object()) return make_error(where + ": expected an object with \"bone\" and \"position\" and/or \"velocity\"");
  for (const auto& item : object.items()) {
    if (item.key() != "bone" && item.key() != "position" && item.key() != "velocity") {
      return make_error(where + "." + printable_text(item.key()) + ": unknown field (expected bone, position, velocity)");
    }
  }
  PoseTarget target;
  if (!object.contains("bone")) return make_error(where + ".bone: missing");
  if (!object["bone"].is_string() || object["bone"].get<std::string>().empty()) {
    return make_error(where + ".bone: expected a bone name or role (\"@left_foot\")");
  }
  target.bone = object["bone"].get<std::string>();
  if (object.contains("position")) {
    MMVK_ASSIGN_OR_RETURN(target.position, read_vec3(object["position"], where + ".position"));
  }
  if (object.contains("velocity")) {
    MMVK_ASSIGN_OR_RETURN(target.velocity, read_vec3(object["velocity"], where + ".velocity"));
  }
  if (!target.position && !target.velocity) return make_error(where + ": needs a \"position\" or a \"velocity\"");
  return target;
}

// The bone a channel measures: its own, or its kind's default.
std::string channel_bone(const FeatureChannel& channel) {
  return channel.bone.empty() ? std::string(channel_kind_info(channel.kind).default_bone) : channel.bone;
}

// Same joint: the same name, or (with the database's skeleton) the same
// joint once names and roles are resolved.
bool same_bone(const Database& database, const std::string& a, const std::string& b) {
  if (a == b) return true;
  const AnimationData* animation = database.animation();
  if (!animation) return false;
  const Result<int> ja = find_bone(animation->skeleton, a);
  const Result<int> jb = find_bone(animation->skeleton, b);
  return ja.ok() && jb.ok() && *ja == *jb;
}

bool measures_velocity(ChannelKind kind) { return kind == ChannelKind::BoneVelocity || kind == ChannelKind::RootVelocity; }

// The schema index of the channel of `kind` (a velocity kind when velocity)
// for `bone`, or -1.
int find_channel(const Database& database, const std::string& bone, bool velocity) {
  const FeatureSchema& schema = database.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    const bool wanted = velocity ? measures_velocity(channel.kind) : channel.kind == ChannelKind::BonePosition;
    if (wanted && same_bone(database, bone, channel_bone(channel))) return static_cast<int>(c);
  }
  return -1;
}

std::string channels_of(const Database& database, bool velocity) {
  std::string out;
  for (const FeatureChannel& channel : database.schema().channels) {
    const bool wanted = velocity ? measures_velocity(channel.kind) : channel.kind == ChannelKind::BonePosition;
    if (!wanted) continue;
    out += (out.empty() ? "" : ", ") + channel.name + " (" + channel_bone(channel) + ")";
  }
  return out.empty() ? "none" : out;
}

// The channel's raw values at `frame`, undoing the normalization.
glm::vec3 raw_values(const Database& database, std::uint32_t frame, std::size_t channel) {
  const std::uint32_t first = database.schema().offset(channel);
  glm::vec3 out(0.0f);
  for (std::uint32_t i = 0; i < 3; ++i) {
    const DimNormalization& n = database.normalization()[first + i];
    out[static_cast<int>(i)] = database.row(frame)[first + i] * n.scale + n.offset;
  }
  return out;
}

}  // namespace

Result<std::vector<PoseTarget>> parse_pose_targets_json(std::string_view json_text, std::string_view source) {
  const std::string name(source.empty() ? std::string_view("pose targets") : source);
  MMVK_ASSIGN_OR_RETURN(const Json root, detail::parse_json_text(json_text, name));
  if (!root.is_object()) return make_error(name + ": expected a JSON object with \"targets\"");
  for (const auto& item : root.items()) {
    if (item.key() != "targets") {
      return make_error(name + ": " + printable_text(item.key()) + ": unknown field (expected targets)");
    }
  }
  if (!root.contains("targets") || !root["targets"].is_array()) {
    return make_error(name + ": targets: expected an array of {\"bone\", \"position\", \"velocity\"}");
  }
  const Json& list = root["targets"];
  if (list.empty()) return make_error(name + ": targets: empty");
  std::vector<PoseTarget> targets;
  for (std::size_t i = 0; i < list.size(); ++i) {
    MMVK_ASSIGN_OR_RETURN(PoseTarget target, read_target(list[i], name + ": targets[" + std::to_string(i) + "]"));
    targets.push_back(std::move(target));
  }
  return targets;
}

Result<std::vector<PoseTarget>> load_pose_targets(const std::filesystem::path& path) {
  MMVK_ASSIGN_OR_RETURN(const std::string text, read_file(path, ReadOptions{kMaxJsonBytes, false}));
  return parse_pose_targets_json(text, path.string());
}

Result<PoseQuery> build_pose_query(const Database& database, std::span<const PoseTarget> targets,
                                   std::string_view source) {
  const std::string name(source);
  if (targets.empty()) return make_error(name + ": targets: empty");
  const FeatureSchema& schema = database.schema();
  std::vector<float> raw(database.dims(), 0.0f);
  // Untargeted dims take the database's mean-ish offset (their weight is 0,
  // so any finite value would do; this one keeps the normalized value 0).
  for (std::uint32_t d = 0; d < database.dims(); ++d) raw[d] = database.normalization()[d].offset;
  PoseQuery query;
  std::set<std::size_t> used;
  std::vector<std::string> fields;  // per query.channels entry, for messages
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PoseTarget& target = targets[i];
    const std::string where = name + ": targets[" + std::to_string(i) + "]";
    for (const bool velocity : {false, true}) {
      const std::optional<glm::vec3>& value = velocity ? target.velocity : target.position;
      if (!value) continue;
      const int channel = find_channel(database, target.bone, velocity);
      const char* field = velocity ? ".velocity" : ".position";
      if (channel < 0) {
        return make_error(where + field + ": the database has no " +
                          (velocity ? "bone_velocity or root_velocity" : "bone_position") + " channel for bone '" +
                          target.bone + "' (it has: " + channels_of(database, velocity) + ")");
      }
      const std::size_t c = static_cast<std::size_t>(channel);
      if (!used.insert(c).second) {
        return make_error(where + field + ": channel '" + schema.channels[c].name + "' is already set by an earlier target");
      }
      const std::uint32_t first = schema.offset(c);
      for (int k = 0; k < 3; ++k) raw[first + static_cast<std::uint32_t>(k)] = (*value)[k];
      query.channels.push_back(c);
      fields.push_back(where + field);
    }
  }
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    if (!used.count(c)) query.params.channel_weights[c] = 0.0f;
  }
  query.features.resize(database.dims());
  database.normalize(raw, query.features);
  // A target far outside the data would make every cost overflow; the
  // search would say so without naming the target. The same bound as the
  // search's, summed target by target to name the one that tips it over.
  double total = 0.0;
  for (std::size_t i = 0; i < query.channels.size(); ++i) {
    const std::size_t c = query.channels[i];
    total += double(query.params.channel_weights[c]) * detail::channel_distance_bound(database, query.features, c);
    if (!(double(database.max_multiplier()) * total + double(database.max_abs_bias()) <= detail::kMaxCostBound)) {
      return make_error(fields[i] + ": too far from anything in the database (its costs would overflow float)");
    }
  }
  return query;
}

std::vector<PoseTargetError> pose_target_errors(const Database& database, std::uint32_t frame,
                                                std::span<const PoseTarget> targets) {
  std::vector<PoseTargetError> out(targets.size());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const PoseTarget& target = targets[i];
    if (target.position) {
      const int c = find_channel(database, target.bone, false);
      if (c >= 0) out[i].position_metres = glm::length(raw_values(database, frame, std::size_t(c)) - *target.position);
    }
    if (target.velocity) {
      const int c = find_channel(database, target.bone, true);
      if (c >= 0) {
        out[i].velocity_metres_per_second = glm::length(raw_values(database, frame, std::size_t(c)) - *target.velocity);
      }
    }
  }
  return out;
}

}  // namespace mmvk
