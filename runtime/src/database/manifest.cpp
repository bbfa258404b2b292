#include "mmvk/database/manifest.hpp"
#include "mmvk/import/scene_import.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <system_error>

#include <nlohmann/json.hpp>

#include "common/json_parse.hpp"
#include "common/name_table.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/input_text.hpp"

namespace mmvk {

namespace {

using Json = nlohmann::json;
using detail::json_float;

Status check_fields(const Json& object, const std::string& where, const std::set<std::string>& known) {
  for (const auto& item : object.items()) {
    // `where` is either "file: " (top level) or "file: clips[2]" (nested).
    const bool top = !where.empty() && where.back() == ' ';
    if (!known.count(item.key())) {
      return make_error(where + (top ? "" : ".") + printable_text(item.key()) + ": unknown field");
    }
  }
  return {};
}

Result<bool> read_bool(const Json& value, const std::string& where) {
  if (!value.is_boolean()) return make_error(where + ": expected true or false");
  return value.get<bool>();
}

Result<std::string> read_string(const Json& value, const std::string& where) {
  if (!value.is_string()) return make_error(where + ": expected a string");
  return value.get<std::string>();
}

// A file name: the OS would read it only up to a NUL ("131_01.bvh\u0000.junk"
// built 131_01.bvh), so one is refused.
Result<std::string> read_path(const Json& value, const std::string& where) {
  MMVK_ASSIGN_OR_RETURN(std::string path, read_string(value, where));
  if (const std::size_t nul = path.find('\0'); nul != std::string::npos) {
    return make_error(where + ": the path holds a NUL byte at offset " + std::to_string(nul));
  }
  return path;
}

Result<TimeRange> read_range(const Json& pair, const std::string& at) {
  if (!pair.is_array() || pair.size() != 2) return make_error(at + ": expected [begin, end] in seconds");
  Result<float> begin = json_float(pair[0], at + "[0]");
  if (!begin.ok()) return begin.error();
  Result<float> end = json_float(pair[1], at + "[1]");
  if (!end.ok()) return end.error();
  if (*begin < 0.0f || !(*end > *begin)) {
    return make_error(at + ": expected 0 <= begin < end, got [" + std::to_string(*begin) + ", " +
                      std::to_string(*end) + "]");
  }
  return TimeRange{*begin, *end};
}

Result<std::vector<TimeRange>> read_ranges(const Json& value, const std::string& where) {
  if (!value.is_array()) return make_error(where + ": expected an array of [begin, end] pairs in seconds");
  std::vector<TimeRange> ranges;
  for (std::size_t i = 0; i < value.size(); ++i) {
    Result<TimeRange> range = read_range(value[i], where + "[" + std::to_string(i) + "]");
    if (!range.ok()) return range.error();
    ranges.push_back(*range);
  }
  return ranges;
}

Result<float> read_multiplier(const Json& value, const std::string& where) {
  Result<float> multiplier = json_float(value, where);
  if (multiplier.ok() && !(*multiplier > 0.0f)) return make_error(where + ": must be > 0");
  return multiplier;
}

// A manifest's own tag: not empty, and not one of the measured gait tags'
// names (gait_bands.hpp), which the build adds itself.
Status check_tag_name(const std::string& tag, const std::string& where) {
  if (tag.empty()) return make_error(where + ": empty tag");
  if (tag.starts_with(kGaitTagPrefix)) {
    return make_error(where + ": '" + printable_text(tag) + "' begins with '" + std::string(kGaitTagPrefix) +
                      "', which is kept for the tags the build measures (gait:stand, gait:walk, gait:jog, "
                      "gait:run, gait:start, gait:stop); name it otherwise");
  }
  return {};
}

Result<std::vector<TagRange>> read_tag_ranges(const Json& value, const std::string& where) {
  if (!value.is_object()) return make_error(where + ": expected an object {\"tag\": [[begin, end], ...]}");
  std::vector<TagRange> out;
  for (const auto& item : value.items()) {
    if (item.key().empty()) return make_error(where + ": empty tag name");
    MMVK_TRY(check_tag_name(item.key(), where + "." + printable_text(item.key())));
    Result<std::vector<TimeRange>> ranges = read_ranges(item.value(), where + "." + item.key());
    if (!ranges.ok()) return ranges.error();
    for (const TimeRange& range : *ranges) out.push_back({item.key(), range});
  }
  return out;
}

Result<std::vector<CostRange>> read_cost_ranges(const Json& value, const std::string& where) {
  if (!value.is_array()) return make_error(where + ": expected an array of {\"range\": [begin, end], \"cost_multiplier\", \"cost_bias\"}");
  std::vector<CostRange> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string at = where + "[" + std::to_string(i) + "]";
    const Json& object = value[i];
    if (!object.is_object()) return make_error(at + ": expected an object with \"range\"");
    MMVK_TRY(check_fields(object, at, {"range", "cost_multiplier", "cost_bias"}));
    if (!object.contains("range")) return make_error(at + ".range: missing");
    Result<TimeRange> range = read_range(object["range"], at + ".range");
    if (!range.ok()) return range.error();
    CostRange cost;
    cost.range = *range;
    if (object.contains("cost_multiplier")) {
      Result<float> m = read_multiplier(object["cost_multiplier"], at + ".cost_multiplier");
      if (!m.ok()) return m.error();
      cost.cost_multiplier = *m;
    }
    if (object.contains("cost_bias")) {
      Result<float> b = json_float(object["cost_bias"], at + ".cost_bias");
      if (!b.ok()) return b.error();
      cost.cost_bias = *b;
    }
    out.push_back(cost);
  }
  return out;
}

// Assigns a parsed value to an existing target or returns its error; one
// statement (do-while), so it fits an unbraced `if`, which
// MMVK_ASSIGN_OR_RETURN (it may declare its target) does not.
#define MMVK_READ(target, expr)          \
  do {                                   \
    auto mmvk_read_ = (expr);            \
    if (!mmvk_read_.ok()) return mmvk_read_.error(); \
    target = std::move(*mmvk_read_);     \
  } while (false)

Result<ManifestClip> parse_clip(const Json& object, const std::string& where, const std::filesystem::path& base_dir) {
  if (object.is_string()) {
    ManifestClip clip;
    clip.field = where;
    MMVK_ASSIGN_OR_RETURN(const std::string file, read_path(object, where));
    clip.file = base_dir / file;
    clip.name = clip.file.stem().string();
    return clip;
  }
  if (!object.is_object()) return make_error(where + ": expected an object (or a file name)");
  MMVK_TRY(check_fields(object, where,
                        {"file", "animation", "range", "name", "tags", "loop", "mirror", "cost_multiplier", "cost_bias",
                         "do_not_use", "block_transition", "tag_ranges", "cost_ranges"}));
  ManifestClip clip;
  clip.field = where;
  if (!object.contains("file")) return make_error(where + ".file: missing");
  std::string file;
  MMVK_READ(file, read_path(object["file"], where + ".file"));
  if (file.empty()) return make_error(where + ".file: empty");
  clip.file = base_dir / file;
  clip.name = clip.file.stem().string();
  if (object.contains("animation")) {
    MMVK_READ(clip.animation, read_string(object["animation"], where + ".animation"));
    if (clip.animation.empty()) return make_error(where + ".animation: empty (leave it out for every animation)");
  }
  if (object.contains("range")) MMVK_READ(clip.range, read_range(object["range"], where + ".range"));
  if (object.contains("name")) MMVK_READ(clip.name, read_string(object["name"], where + ".name"));
  if (object.contains("tags")) {
    const Json& tags = object["tags"];
    if (!tags.is_array()) return make_error(where + ".tags: expected an array of strings");
    for (std::size_t i = 0; i < tags.size(); ++i) {
      std::string tag;
      MMVK_READ(tag, read_string(tags[i], where + ".tags[" + std::to_string(i) + "]"));
      MMVK_TRY(check_tag_name(tag, where + ".tags[" + std::to_string(i) + "]"));
      if (std::find(clip.tags.begin(), clip.tags.end(), tag) == clip.tags.end()) clip.tags.push_back(tag);
    }
  }
  if (object.contains("loop")) MMVK_READ(clip.loop, read_bool(object["loop"], where + ".loop"));
  if (object.contains("mirror")) MMVK_READ(clip.mirror, read_bool(object["mirror"], where + ".mirror"));
  if (object.contains("cost_multiplier")) {
    MMVK_READ(clip.cost_multiplier, read_multiplier(object["cost_multiplier"], where + ".cost_multiplier"));
  }
  if (object.contains("cost_bias")) MMVK_READ(clip.cost_bias, json_float(object["cost_bias"], where + ".cost_bias"));
  if (object.contains("do_not_use")) {
    MMVK_READ(clip.do_not_use, read_ranges(object["do_not_use"], where + ".do_not_use"));
  }
  if (object.contains("block_transition")) {
    MMVK_READ(clip.block_transition, read_ranges(object["block_transition"], where + ".block_transition"));
  }
  if (object.contains("tag_ranges")) {
    MMVK_READ(clip.tag_ranges, read_tag_ranges(object["tag_ranges"], where + ".tag_ranges"));
  }
  if (object.contains("cost_ranges")) {
    MMVK_READ(clip.cost_ranges, read_cost_ranges(object["cost_ranges"], where + ".cost_ranges"));
  }
  return clip;
}

Result<std::vector<BonePair>> read_bone_pairs(const Json& value, const std::string& where) {
  if (!value.is_array()) return make_error(where + ": expected an array of [left, right] bone names");
  std::vector<BonePair> out;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::string at = where + "[" + std::to_string(i) + "]";
    const Json& pair = value[i];
    if (!pair.is_array() || pair.size() != 2) return make_error(at + ": expected [left, right] bone names");
    BonePair bones;
    MMVK_READ(bones.first, read_string(pair[0], at + "[0]"));
    MMVK_READ(bones.second, read_string(pair[1], at + "[1]"));
    if (bones.first.empty()) return make_error(at + "[0]: empty bone name");
    if (bones.second.empty()) return make_error(at + "[1]: empty bone name");
    out.push_back(std::move(bones));
  }
  return out;
}

Result<std::uint32_t> read_dim(const Json& value, std::uint32_t dims, const std::string& where) {
  if (!value.is_number_integer() || value.get<std::int64_t>() < 0 || value.get<std::int64_t>() >= dims) {
    return make_error(where + ": expected a dim index in [0, " + std::to_string(dims) + ")");
  }
  return static_cast<std::uint32_t>(value.get<std::int64_t>());
}

Result<SidecarMirror> read_sidecar_mirror(const Json& value, const FeatureChannel& channel, const std::string& where) {
  if (!value.is_object()) return make_error(where + ": expected an object with \"swap\" and/or \"negate\"");
  MMVK_TRY(check_fields(value, where, {"swap", "negate"}));
  const std::uint32_t dims = channel.custom_dims;
  SidecarMirror out;
  out.channel = channel.name;
  out.sign.assign(dims, 1.0f);
  for (std::uint32_t d = 0; d < dims; ++d) out.source.push_back(d);
  std::vector<bool> swapped(dims, false);
  if (value.contains("swap")) {
    const Json& swaps = value["swap"];
    if (!swaps.is_array()) return make_error(where + ".swap: expected an array of [dim, dim] pairs");
    for (std::size_t i = 0; i < swaps.size(); ++i) {
      const std::string at = where + ".swap[" + std::to_string(i) + "]";
      if (!swaps[i].is_array() || swaps[i].size() != 2) return make_error(at + ": expected [dim, dim]");
      std::uint32_t a = 0;
      std::uint32_t b = 0;
      MMVK_READ(a, read_dim(swaps[i][0], dims, at + "[0]"));
      MMVK_READ(b, read_dim(swaps[i][1], dims, at + "[1]"));
      if (a == b) return make_error(at + ": a dim cannot swap with itself");
      if (swapped[a] || swapped[b]) {
        return make_error(at + ": dim " + std::to_string(swapped[a] ? a : b) + " is already in an earlier swap");
      }
      swapped[a] = swapped[b] = true;
      out.source[a] = b;
      out.source[b] = a;
    }
  }
  if (value.contains("negate")) {
    const Json& negate = value["negate"];
    if (!negate.is_array()) return make_error(where + ".negate: expected an array of dims");
    for (std::size_t i = 0; i < negate.size(); ++i) {
      const std::string at = where + ".negate[" + std::to_string(i) + "]";
      std::uint32_t d = 0;
      MMVK_READ(d, read_dim(negate[i], dims, at));
      if (out.sign[d] < 0.0f) return make_error(at + ": dim " + std::to_string(d) + " is listed twice");
      out.sign[d] = -1.0f;
    }
  }
  return out;
}

Result<std::vector<SidecarMirror>> read_mirror_map(const Json& value, const FeatureSchema& schema,
                                                   const std::string& where) {
  if (!value.is_object()) return make_error(where + ": expected an object {\"channel\": {\"swap\", \"negate\"}}");
  std::vector<SidecarMirror> out;
  for (const auto& item : value.items()) {
    const std::string at = where + "." + item.key();
    const FeatureChannel* channel = nullptr;
    for (const FeatureChannel& c : schema.channels) {
      if (c.name == item.key()) channel = &c;
    }
    if (!channel) return make_error(at + ": the schema has no channel named '" + item.key() + "'");
    if (!reads_sidecar(channel->kind)) {
      return make_error(at + ": channel '" + item.key() + "' is a " + std::string(channel_kind_name(channel->kind)) +
                        " channel, measured again on the mirrored motion; only sidecar (custom) channels take a mirror map");
    }
    Result<SidecarMirror> mirror = read_sidecar_mirror(item.value(), *channel, at);
    if (!mirror.ok()) return mirror.error();
    out.push_back(std::move(*mirror));
  }
  return out;
}

// The "contacts" block: any subset of FootContactParams' fields, by their
// names; the result is validated whole (exit >= enter needs both).
Result<FootContactParams> read_contacts(const Json& value, const std::string& where) {
  if (!value.is_object()) return make_error(where + ": expected an object");
  FootContactParams params;
  std::set<std::string> known = {"height_above_clip_floor"};
  for_each_contact_bone(params, [&](const char* name, std::string&) { known.insert(name); });
  for_each_contact_number(params, [&](const char* name, float&) { known.insert(name); });
  MMVK_TRY(check_fields(value, where, known));
  std::optional<Error> error;
  auto read = [&](const char* name, auto& target, auto parse) {
    if (error || !value.contains(name)) return;
    auto parsed = parse(value[name], where + "." + name);
    if (parsed.ok()) {
      target = *parsed;
    } else {
      error = parsed.error();
    }
  };
  for_each_contact_bone(params, [&](const char* name, std::string& bone) { read(name, bone, read_string); });
  for_each_contact_number(params, [&](const char* name, float& number) { read(name, number, json_float); });
  read("height_above_clip_floor", params.height_above_clip_floor, read_bool);
  if (error) return *error;
  MMVK_TRY(validate_foot_contact_params(params, where));
  return params;
}

// The "gait_bands" block: any subset of GaitBandParams' fields by name,
// validated whole (the thresholds' order needs all three).
Result<GaitBandParams> read_gait_bands(const Json& value, const std::string& where) {
  if (!value.is_object()) return make_error(where + ": expected an object");
  GaitBandParams params;
  const std::pair<const char*, float*> numbers[] = {
      {"walk_from_mps", &params.walk_from_mps},          {"jog_from_mps", &params.jog_from_mps},
      {"run_from_mps", &params.run_from_mps},            {"hysteresis", &params.hysteresis},
      {"smoothing_seconds", &params.smoothing_seconds}, {"transition_seconds", &params.transition_seconds}};
  std::set<std::string> known = {"enabled"};
  for (const auto& [name, target] : numbers) known.insert(name);
  MMVK_TRY(check_fields(value, where, known));
  if (value.contains("enabled")) MMVK_READ(params.enabled, read_bool(value["enabled"], where + ".enabled"));
  for (const auto& [name, target] : numbers) {
    if (value.contains(name)) MMVK_READ(*target, json_float(value[name], where + "." + name));
  }
  MMVK_TRY(validate_gait_band_params(params, where));
  return params;
}

struct EdgeRuleEntry {
  EdgeRule rule;
  std::string_view name;
};
constexpr EdgeRuleEntry kEdgeRules[] = {
    {EdgeRule::Exclude, "exclude"},
    {EdgeRule::Clamp, "clamp"},
    {EdgeRule::Extrapolate, "extrapolate"},
};
static_assert(detail::indexed_by(std::span<const EdgeRuleEntry>(kEdgeRules), &EdgeRuleEntry::rule));

}  // namespace

std::string_view edge_rule_name(EdgeRule rule) {
  return detail::name_for(std::span<const EdgeRuleEntry>(kEdgeRules), &EdgeRuleEntry::name, rule);
}

Result<EdgeRule> parse_edge_rule(std::string_view name) {
  const std::span<const EdgeRuleEntry> table(kEdgeRules);
  if (const EdgeRuleEntry* entry = detail::find_named(table, &EdgeRuleEntry::name, name)) return entry->rule;
  return make_error("expected " + detail::name_list(table, &EdgeRuleEntry::name, '"', true) + ", got " +
                    quoted_text(name));
}

namespace {

// The steps of parse_manifest_json, one top-level field (or group) each;
// `at` is "<manifest>: " for messages.
// "schema": a file beside the manifest, or the schema object inline.
Status read_schema_field(const Json& root, const std::string& name, const std::string& at,
                         const std::filesystem::path& base_dir, Manifest& manifest) {
  if (!root.contains("schema")) return {};
  const Json& schema = root["schema"];
  if (schema.is_string()) {
    MMVK_ASSIGN_OR_RETURN(const std::string file, read_path(schema, at + "schema"));
    std::filesystem::path path = base_dir / file;
    Result<FeatureSchema> loaded = load_schema(path);
    if (!loaded.ok()) return make_error(at + "schema: " + loaded.message());
    manifest.schema = std::move(*loaded);
  } else if (schema.is_object()) {
    Result<FeatureSchema> parsed = parse_schema_json(schema.dump(-1, ' ', false, Json::error_handler_t::replace), name + ": schema");
    if (!parsed.ok()) return parsed.error();
    manifest.schema = std::move(*parsed);
  } else {
    return make_error(at + "schema: expected a file name or a schema object");
  }
  return {};
}

Status read_fps_field(const Json& root, const std::string& at, Manifest& manifest) {
  if (!root.contains("fps")) return {};
  MMVK_READ(manifest.fps, json_float(root["fps"], at + "fps"));
  if (!(manifest.fps >= kMinFps && manifest.fps <= kMaxFps)) {
    char text[120];
    std::snprintf(text, sizeof(text), "fps: %g is outside the supported [%g, %g] frames/s", double(manifest.fps),
                  double(kMinFps), double(kMaxFps));
    return make_error(at + text);
  }
  return {};
}

Status read_import_field(const Json& root, const std::string& at, Manifest& manifest) {
  if (!root.contains("import")) return {};
  const Json& import = root["import"];
  if (!import.is_object()) return make_error(at + "import: expected an object");
  MMVK_TRY(check_fields(import, at + "import", {"metres_per_unit", "up_axis", "accept_implausible"}));
  if (import.contains("accept_implausible")) {
    MMVK_READ(manifest.import.accept_implausible,
              read_bool(import["accept_implausible"], at + "import.accept_implausible"));
  }
  if (import.contains("metres_per_unit")) {
    MMVK_READ(manifest.import.metres_per_unit, json_float(import["metres_per_unit"], at + "import.metres_per_unit"));
    if (manifest.import.metres_per_unit < 0.0f) {
      return make_error(at + "import.metres_per_unit: must be > 0 (or 0 to guess)");
    }
  }
  if (import.contains("up_axis")) {
    std::string axis;
    MMVK_READ(axis, read_string(import["up_axis"], at + "import.up_axis"));
    manifest.import.up_axis_given = true;
    if (axis == "y" || axis == "Y") {
      manifest.import.up_axis = UpAxis::Y;
    } else if (axis == "z" || axis == "Z") {
      manifest.import.up_axis = UpAxis::Z;
    } else {
      return make_error(at + "import.up_axis: expected \"y\" or \"z\", got " + quoted_text(axis));
    }
  }
  return {};
}

Status read_character_root_field(const Json& root, const std::string& at, Manifest& manifest) {
  if (!root.contains("character_root")) return {};
  const Json& options = root["character_root"];
  if (!options.is_object()) return make_error(at + "character_root: expected an object");
  MMVK_TRY(check_fields(options, at + "character_root", {"source_bone", "facing_smoothing_seconds"}));
  if (options.contains("source_bone")) {
    MMVK_READ(manifest.character_root.source_bone,
              read_string(options["source_bone"], at + "character_root.source_bone"));
  }
  if (options.contains("facing_smoothing_seconds")) {
    MMVK_READ(manifest.character_root.facing_smoothing_seconds,
              json_float(options["facing_smoothing_seconds"], at + "character_root.facing_smoothing_seconds"));
    if (manifest.character_root.facing_smoothing_seconds < 0.0f) {
      return make_error(at + "character_root.facing_smoothing_seconds: must be >= 0");
    }
  }
  return {};
}

// "clips", each mirrored too where the manifest's "mirror" says so.
Status read_clips_field(const Json& root, const std::string& at, const std::filesystem::path& base_dir, bool mirror_all,
                        Manifest& manifest) {
  if (!root.contains("clips") || !root["clips"].is_array()) {
    return make_error(at + "clips: expected an array of clips");
  }
  const Json& clips = root["clips"];
  if (clips.empty()) return make_error(at + "clips: empty");
  for (std::size_t i = 0; i < clips.size(); ++i) {
    Result<ManifestClip> clip = parse_clip(clips[i], at + "clips[" + std::to_string(i) + "]", base_dir);
    if (!clip.ok()) return clip.error();
    clip->mirror = clip->mirror || mirror_all;
    manifest.clips.push_back(std::move(*clip));
  }
  return {};
}

}  // namespace

Result<Manifest> parse_manifest_json(std::string_view json_text, std::string_view source,
                                     const std::filesystem::path& base_dir) {
  const std::string name(source.empty() ? std::string_view("manifest") : source);
  Result<Json> parsed = detail::parse_json_text(json_text, name);
  if (!parsed.ok()) return parsed.error();
  const Json root = std::move(*parsed);
  if (!root.is_object()) return make_error(name + ": expected a JSON object with \"clips\"");
  MMVK_TRY(check_fields(root, name + ": ", {"schema", "fps", "import", "character_root", "edge_rule", "mirror", "mirror_bones",
                                          "mirror_map", "contacts", "gait_bands", "crowd", "clips"}));

  Manifest manifest;
  manifest.source = name;
  const std::string at = name + ": ";
  MMVK_TRY(read_schema_field(root, name, at, base_dir, manifest));
  MMVK_TRY(read_fps_field(root, at, manifest));
  MMVK_TRY(read_import_field(root, at, manifest));
  MMVK_TRY(read_character_root_field(root, at, manifest));
  if (root.contains("edge_rule")) {
    std::string rule;
    MMVK_READ(rule, read_string(root["edge_rule"], at + "edge_rule"));
    Result<EdgeRule> parsed_rule = parse_edge_rule(rule);
    if (!parsed_rule.ok()) return make_error(at + "edge_rule: " + parsed_rule.message());
    manifest.edge_rule = *parsed_rule;
  }
  bool mirror_all = false;
  if (root.contains("mirror")) MMVK_READ(mirror_all, read_bool(root["mirror"], at + "mirror"));
  if (root.contains("mirror_bones")) {
    MMVK_READ(manifest.mirror_bones, read_bone_pairs(root["mirror_bones"], at + "mirror_bones"));
  }
  if (root.contains("mirror_map")) {
    MMVK_READ(manifest.mirror_map, read_mirror_map(root["mirror_map"], manifest.schema, at + "mirror_map"));
  }
  if (root.contains("contacts")) MMVK_READ(manifest.contacts, read_contacts(root["contacts"], at + "contacts"));
  if (root.contains("gait_bands")) {
    MMVK_READ(manifest.gait_bands, read_gait_bands(root["gait_bands"], at + "gait_bands"));
  }
  if (root.contains("crowd")) {
    if (!root["crowd"].is_object()) return make_error(at + "crowd: expected an object of crowd settings");
    manifest.crowd = root["crowd"].dump();
  }
  MMVK_TRY(read_clips_field(root, at, base_dir, mirror_all, manifest));
  return manifest;
}

#undef MMVK_READ

Result<Manifest> load_manifest(const std::filesystem::path& path) {
  Result<std::string> text = read_file(path, ReadOptions{kMaxJsonBytes, false});
  if (!text.ok()) return text.error();
  return parse_manifest_json(*text, path.string(), path.parent_path());
}

bool is_bvh_path(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".bvh";
}

bool is_motion_path(const std::filesystem::path& path) { return is_bvh_path(path) || is_scene_path(path); }

namespace {

// The manifest of BVH files with default options, one clip per file named by
// its stem.
Manifest manifest_of_clip_files(std::string source, const std::vector<std::filesystem::path>& files) {
  Manifest manifest;
  manifest.source = std::move(source);
  for (const std::filesystem::path& file : files) {
    ManifestClip clip;
    clip.file = file;
    clip.name = file.stem().string();
    manifest.clips.push_back(std::move(clip));
  }
  return manifest;
}

}  // namespace

Result<Manifest> manifest_from_directory(const std::filesystem::path& dir) {
  std::error_code error;
  std::vector<std::filesystem::path> files;
  for (std::filesystem::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    if (it->is_regular_file(error) && is_motion_path(it->path())) files.push_back(it->path());
  }
  if (error) return make_error(dir.string() + ": cannot list the folder: " + error.message());
  if (files.empty()) return make_error(dir.string() + ": no motion files (.bvh, .fbx, .gltf, .glb, .dae) in the folder");
  std::sort(files.begin(), files.end());
  return manifest_of_clip_files(dir.string(), files);
}

Result<Manifest> load_manifest_or_directory(const std::filesystem::path& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return manifest_from_directory(path);
  if (!std::filesystem::exists(path, error)) return make_error(path.string() + ": no such file or folder");
  // A motion file given where a manifest is expected is one clip, as in a folder.
  if (is_motion_path(path)) return manifest_of_clip_files(path.string(), {path});
  return load_manifest(path);
}

}  // namespace mmvk
