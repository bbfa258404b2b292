// The JSON form of a FeatureSchema (see feature_schema.hpp). Unknown fields
// are errors, so a typo ("weigth") is reported instead of silently ignored.
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "common/json_parse.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/input_text.hpp"
#include "mmvk/features/normalization.hpp"

namespace mmvk {

namespace {

using Json = nlohmann::json;

// The steps of parse_channel, in the order its fields are checked; `kind`
// is the kind's name, for messages. A field the kind would ignore is an
// error, like an unknown field.
Result<const ChannelKindInfo*> parse_name_and_kind(const Json& object, const std::string& where,
                                                   FeatureChannel& channel) {
  if (!object.contains("name") || !object["name"].is_string()) return make_error(where + ".name: expected a string");
  channel.name = object["name"].get<std::string>();
  if (!object.contains("kind") || !object["kind"].is_string()) {
    return make_error(where + ".kind: expected one of " + channel_kind_list());
  }
  const std::string kind = object["kind"].get<std::string>();
  const ChannelKindInfo* info = find_channel_kind(kind);
  if (info == nullptr) {
    return make_error(where + ".kind: unknown kind \"" + kind + "\", expected one of " + channel_kind_list());
  }
  channel.kind = info->kind;
  return info;
}

Status parse_bones(const Json& object, const std::string& where, const ChannelKindInfo& info, const std::string& kind,
                   FeatureChannel& channel) {
  if (object.contains("bone")) {
    if (!has_field(info.fields, ChannelField::Bone)) {
      return make_error(where + ".bone: a " + kind + " channel reads no bone");
    }
    if (!object["bone"].is_string()) return make_error(where + ".bone: expected a string");
    channel.bone = object["bone"].get<std::string>();
  }
  if (object.contains("second_bone")) {
    if (!has_field(info.fields, ChannelField::SecondBone)) {
      return make_error(where + ".second_bone: a " + kind + " channel reads no second bone");
    }
    if (!object["second_bone"].is_string()) return make_error(where + ".second_bone: expected a string");
    channel.second_bone = object["second_bone"].get<std::string>();
  }
  if (object.contains("limb")) {
    // Shorthand for the limb's root and end bones (named_limbs()).
    if (info.kind != ChannelKind::LimbVector) return make_error(where + ".limb: a " + kind + " channel reads no limb");
    if (object.contains("bone") || object.contains("second_bone")) {
      return make_error(where + ".limb: give either limb or bone and second_bone, not both");
    }
    const std::string limb = object["limb"].is_string() ? object["limb"].get<std::string>() : std::string();
    const NamedLimb* named = find_limb(limb);
    if (named == nullptr) {
      return make_error(where + ".limb: unknown limb \"" + limb + "\", expected one of " + limb_list());
    }
    channel.bone = named->root;
    channel.second_bone = named->end;
  }
  return {};
}

Status parse_curves(const Json& object, const std::string& where, const ChannelKindInfo& info, const std::string& kind,
                    FeatureChannel& channel) {
  if (object.contains("curves")) {
    if (!has_field(info.fields, ChannelField::Curves)) {
      return make_error(where + ".curves: a " + kind + " channel reads no curves");
    }
    const Json& curves = object["curves"];
    if (!curves.is_array()) return make_error(where + ".curves: expected an array of strings");
    for (std::size_t i = 0; i < curves.size(); ++i) {
      if (!curves[i].is_string() || curves[i].get<std::string>().empty()) {
        return make_error(where + ".curves[" + std::to_string(i) + "]: expected a non-empty string");
      }
      channel.curves.push_back(curves[i].get<std::string>());
    }
  }
  if (object.contains("window_seconds")) {
    if (!has_field(info.fields, ChannelField::Curves)) {
      return make_error(where + ".window_seconds: a " + kind + " channel has no window");
    }
    Result<float> window = detail::json_float(object["window_seconds"], where + ".window_seconds");
    if (!window.ok()) return window.error();
    channel.window_seconds = *window;
  }
  return {};
}

// offsets_seconds, then dims: a kind's width depends on its offsets and
// curves, read before.
Status parse_offsets_and_dims(const Json& object, const std::string& where, const ChannelKindInfo& info,
                              const std::string& kind, FeatureChannel& channel) {
  if (object.contains("offsets_seconds")) {
    const Json& offsets = object["offsets_seconds"];
    if (!offsets.is_array()) return make_error(where + ".offsets_seconds: expected an array of numbers");
    for (std::size_t i = 0; i < offsets.size(); ++i) {
      Result<float> t = detail::json_float(offsets[i], where + ".offsets_seconds[" + std::to_string(i) + "]");
      if (!t.ok()) return t.error();
      channel.offsets_seconds.push_back(*t);
    }
  }
  if (object.contains("dims")) {
    const Json& dims = object["dims"];
    if (!dims.is_number_integer() || dims.get<std::int64_t>() <= 0 || dims.get<std::int64_t>() > 4096) {
      return make_error(where + ".dims: expected an integer in [1, 4096]");
    }
    if (has_field(info.fields, ChannelField::Dims)) {
      channel.custom_dims = static_cast<std::uint32_t>(dims.get<std::int64_t>());
    } else {
      const std::int64_t expected = channel.dims();
      if (dims.get<std::int64_t>() != expected) {
        return make_error(where + ".dims: a " + kind + " channel has " + std::to_string(expected) + " dims, not " +
                          std::to_string(dims.get<std::int64_t>()));
      }
    }
  }
  return {};
}

Status parse_weighting(const Json& object, const std::string& where, FeatureChannel& channel) {
  if (object.contains("weight")) {
    Result<float> weight = detail::json_float(object["weight"], where + ".weight");
    if (!weight.ok()) return weight.error();
    channel.weight = *weight;
  }
  if (object.contains("normalization")) {
    const Json& mode = object["normalization"];
    const NormalizationInfo* info = mode.is_string() ? find_normalization(mode.get<std::string>()) : nullptr;
    if (info == nullptr) return make_error(where + ".normalization: expected one of " + normalization_list());
    channel.normalization = info->mode;
  }
  return {};
}

Result<FeatureChannel> parse_channel(const Json& object, const std::string& where) {
  if (!object.is_object()) return make_error(where + ": expected an object");
  static const std::set<std::string> kKnown = {"name",   "kind",          "bone",   "second_bone",    "limb",
                                               "curves", "offsets_seconds", "dims", "window_seconds", "weight",
                                               "normalization"};
  for (const auto& item : object.items()) {
    if (!kKnown.count(item.key())) return make_error(where + "." + printable_text(item.key()) + ": unknown field");
  }
  FeatureChannel channel;
  MMVK_ASSIGN_OR_RETURN(const ChannelKindInfo* const info, parse_name_and_kind(object, where, channel));
  const std::string kind = object["kind"].get<std::string>();
  MMVK_TRY(parse_bones(object, where, *info, kind, channel));
  MMVK_TRY(parse_curves(object, where, *info, kind, channel));
  MMVK_TRY(parse_offsets_and_dims(object, where, *info, kind, channel));
  MMVK_TRY(parse_weighting(object, where, channel));
  return channel;
}

}  // namespace

Result<FeatureSchema> parse_schema_json(std::string_view json_text, std::string_view source) {
  const std::string name(source.empty() ? std::string_view("schema") : source);
  Result<Json> parsed = detail::parse_json_text(json_text, name);
  if (!parsed.ok()) return parsed.error();
  Json root = std::move(*parsed);
  if (!root.is_object()) return make_error(name + ": expected a JSON object with \"channels\"");
  for (const auto& item : root.items()) {
    if (item.key() != "channels") return make_error(name + ": " + printable_text(item.key()) + ": unknown field");
  }
  if (!root.contains("channels") || !root["channels"].is_array()) {
    return make_error(name + ": channels: expected an array of channel objects");
  }
  FeatureSchema schema;
  const Json& channels = root["channels"];
  for (std::size_t i = 0; i < channels.size(); ++i) {
    Result<FeatureChannel> channel = parse_channel(channels[i], name + ": channels[" + std::to_string(i) + "]");
    if (!channel.ok()) return channel.error();
    schema.channels.push_back(std::move(*channel));
  }
  Status valid = schema.validate();
  if (!valid.ok()) return make_error(name + ": " + valid.message());
  return schema;
}

Result<FeatureSchema> load_schema(const std::filesystem::path& path) {
  Result<std::string> text = read_file(path, ReadOptions{kMaxJsonBytes, false});
  if (!text.ok()) return text.error();
  return parse_schema_json(*text, path.string());
}

std::string schema_to_json(const FeatureSchema& schema) {
  Json channels = Json::array();
  for (const FeatureChannel& channel : schema.channels) {
    Json object;
    object["name"] = channel.name;
    const ChannelKindInfo& info = channel_kind_info(channel.kind);
    object["kind"] = info.name;
    if (!channel.bone.empty()) object["bone"] = channel.bone;
    if (!channel.second_bone.empty()) object["second_bone"] = channel.second_bone;
    if (has_field(info.fields, ChannelField::Offsets)) object["offsets_seconds"] = channel.offsets_seconds;
    if (has_field(info.fields, ChannelField::Dims)) object["dims"] = channel.custom_dims;
    if (has_field(info.fields, ChannelField::Curves)) {
      object["curves"] = channel.curves;
      object["window_seconds"] = channel.window_seconds;
    }
    object["weight"] = channel.weight;
    object["normalization"] = normalization_name(channel.normalization);
    channels.push_back(std::move(object));
  }
  Json root;
  root["channels"] = std::move(channels);
  return root.dump(2, ' ', false, Json::error_handler_t::replace);  // names from a file: never throw on bad UTF-8
}

}  // namespace mmvk
