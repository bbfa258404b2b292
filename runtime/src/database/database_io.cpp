#include "mmvk/database/database_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <span>

#include "mmvk/import/character.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/hash.hpp"
#include "common/byte_codec.hpp"

namespace mmvk {

namespace {

using detail::Reader;
using detail::Writer;

constexpr char kMagic[8] = {'M', 'M', 'V', 'K', 'D', 'B', '\n', '\0'};

std::uint64_t read_u64_at(std::string_view bytes, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{static_cast<std::uint8_t>(bytes[at + i])} << (8 * i);
  return v;
}

std::uint32_t read_u32_at(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t{static_cast<std::uint8_t>(bytes[at + i])} << (8 * i);
  return v;
}

// Quantized16 rotations: each component of the unit quaternion (sign made
// w >= 0) times 32767, rounded; renormalized on load. The worst-case angle
// error is about 4e-3 degree (tests/data/animation_data_test.cpp measures it).
std::int16_t quantize(float c) { return static_cast<std::int16_t>(std::lround(std::clamp(c, -1.0f, 1.0f) * 32767.0f)); }

// The contact setup of a version 5 animation section: the joints and the
// detection parameters (database_io.hpp).
void write_contact_setup(Writer& file, const AnimationData& a) {
  for (const auto& joints : {a.contact_joints, a.heel_joints}) {
    for (int j : joints) file.u32(static_cast<std::uint32_t>(j));
  }
  const FootContactParams& c = a.contact_params;
  for_each_contact_bone(c, [&](const char*, const std::string& bone) { file.str(bone); });
  for_each_contact_number(c, [&](const char*, float value) { file.f32(value); });
  file.u8(c.height_above_clip_floor ? 1 : 0);
}

std::string read_contact_setup(Reader& in, AnimationData& a) {
  for (auto* joints : {&a.contact_joints, &a.heel_joints}) {
    for (int& j : *joints) {
      std::uint32_t v = 0;
      if (!in.u32(v)) return "animation contact joints";
      j = static_cast<int>(v);
    }
  }
  FootContactParams& c = a.contact_params;
  bool read = true;
  for_each_contact_bone(c, [&](const char*, std::string& bone) { read = read && in.str(bone); });
  for_each_contact_number(c, [&](const char*, float& value) { read = read && in.f32(value); });
  std::uint8_t above_floor = 0;
  if (!read || !in.u8(above_floor)) return "animation contact parameters";
  if (above_floor > 1) return "contact height mode";
  c.height_above_clip_floor = above_floor != 0;
  return {};
}

// Versions 2 to 4: one contact joint per side (the toe, or the ankle where
// the skeleton has none) and one threshold pair on 3-D speed. Kept as
// thresholds that mean the same (enter = exit, no minimum durations).
std::string read_legacy_contact_setup(Reader& in, AnimationData& a) {
  std::uint32_t left = 0;
  std::uint32_t right = 0;
  std::uint8_t above_floor = 0;
  FootContactParams& c = a.contact_params;
  if (!in.u32(left) || !in.u32(right) || !in.str(c.left_toe) || !in.str(c.right_toe) || !in.f32(c.enter_height) ||
      !in.f32(c.enter_speed) || !in.f32(c.heel_height_extra) || !in.u8(above_floor) || !in.f32(c.floor_percentile)) {
    return "animation contacts";
  }
  if (above_floor > 1) return "contact height mode";
  c.height_above_clip_floor = above_floor != 0;
  c.exit_height = c.enter_height;
  c.exit_speed = c.enter_speed;
  c.min_contact_seconds = 0.0f;
  c.min_gap_seconds = 0.0f;
  c.speed_step_seconds = 0.0f;  // central differences, in fact
  a.contact_joints = {static_cast<int>(left), static_cast<int>(right)};
  a.legacy_contacts = true;
  return {};
}

// A legacy file's planted bits gain the bit of the point they were detected
// on: the heel where the contact joint is the ankle, else the toe.
void relabel_legacy_contacts(AnimationData& a) {
  std::uint8_t point[2] = {};
  for (int s = 0; s < 2; ++s) {
    const std::size_t side = static_cast<std::size_t>(s);
    Result<int> ankle = find_bone(a.skeleton, s == 0 ? a.contact_params.left_heel : a.contact_params.right_heel);
    a.heel_joints[side] = ankle.ok() ? *ankle : -1;
    point[side] = ankle.ok() && *ankle == a.contact_joints[side] ? contact_heel_bit(s) : contact_toe_bit(s);
  }
  for (std::uint8_t& bits : a.contacts) {
    for (int s = 0; s < 2; ++s) {
      if (bits & contact_planted_bit(s)) bits |= point[s];
    }
  }
}

void write_animation(Writer& file, const AnimationData& a) {
  file.u32(static_cast<std::uint32_t>(a.joint_count()));
  for (std::size_t j = 0; j < a.joint_count(); ++j) {
    file.str(a.skeleton.names[j]);
    file.u32(static_cast<std::uint32_t>(a.skeleton.parents[j]));
    file.f32(a.skeleton.rest_offsets[j].x);
    file.f32(a.skeleton.rest_offsets[j].y);
    file.f32(a.skeleton.rest_offsets[j].z);
    file.u32(static_cast<std::uint32_t>(a.mirror_pairs[j]));
  }
  file.u32(static_cast<std::uint32_t>(a.translated_joints.size()));
  for (std::uint32_t j : a.translated_joints) file.u32(j);
  write_contact_setup(file, a);
  file.u8(static_cast<std::uint8_t>(a.encoding));
  file.u32(a.frame_count);
  for (const glm::quat& q : a.local_rotations) {
    const float s = q.w < 0.0f ? -1.0f : 1.0f;
    if (a.encoding == RotationEncoding::Quantized16) {
      for (float c : {q.x, q.y, q.z, q.w}) file.i16(quantize(s * c));
    } else {
      for (float c : {q.x, q.y, q.z, q.w}) file.f32(c);
    }
  }
  for (const glm::vec3& t : a.local_translations) {
    file.f32(t.x);
    file.f32(t.y);
    file.f32(t.z);
  }
  for (const glm::vec3& p : a.root_positions) {
    file.f32(p.x);
    file.f32(p.z);
  }
  file.f32_array(a.root_yaws);
  for (std::uint8_t c : a.contacts) file.u8(c);
}

// Reads the section; sizes are checked against what is left before any
// allocation. Returns an empty string on success, else what is corrupt.
std::string read_animation(Reader& in, std::uint32_t version, AnimationData& a) {
  std::uint32_t joints = 0;
  if (!in.u32(joints) || std::uint64_t{joints} * 24 > in.left()) return "animation joint count";
  a.skeleton.names.resize(joints);
  a.skeleton.parents.resize(joints);
  a.skeleton.rest_offsets.resize(joints);
  a.mirror_pairs.resize(joints);
  for (std::uint32_t j = 0; j < joints; ++j) {
    std::uint32_t parent = 0;
    std::uint32_t pair = 0;
    glm::vec3& r = a.skeleton.rest_offsets[j];
    if (!in.str(a.skeleton.names[j]) || !in.u32(parent) || !in.f32(r.x) || !in.f32(r.y) || !in.f32(r.z) ||
        !in.u32(pair)) {
      return "animation joint";
    }
    a.skeleton.parents[j] = static_cast<int>(parent);
    a.mirror_pairs[j] = static_cast<int>(pair);
  }
  std::uint32_t translated = 0;
  if (!in.u32(translated) || std::uint64_t{translated} * 4 > in.left()) return "translated joint count";
  a.translated_joints.resize(translated);
  for (std::uint32_t& j : a.translated_joints) {
    if (!in.u32(j)) return "translated joints";
  }
  if (version >= 5) {
    if (std::string what = read_contact_setup(in, a); !what.empty()) return what;
  } else if (std::string what = read_legacy_contact_setup(in, a); !what.empty()) {
    return what;
  }
  std::uint8_t encoding = 0;
  if (!in.u8(encoding) || !in.u32(a.frame_count)) return "animation encoding and frame count";
  if (encoding > static_cast<std::uint8_t>(RotationEncoding::Quantized16)) return "rotation encoding";
  a.encoding = static_cast<RotationEncoding>(encoding);
  const std::uint64_t frames = a.frame_count;
  const std::uint64_t rotation_bytes = a.encoding == RotationEncoding::Float32 ? 16 : 8;
  // joints and translated are bounded by the bytes left, so per_frame fits;
  // frames is compared by division first, so frames * per_frame cannot wrap
  // around 2^64 to the bytes left (as a cluster table header once did).
  const std::uint64_t per_frame = joints * rotation_bytes + translated * 12 + 8 + 4 + 1;
  if (frames > in.left() / per_frame || frames * per_frame != in.left()) {
    return "animation of " + std::to_string(frames) + " frames of " + std::to_string(per_frame) +
           " bytes each does not fill the " + std::to_string(in.left()) + " bytes left";
  }
  a.local_rotations.resize(frames * joints);
  for (glm::quat& q : a.local_rotations) {
    if (a.encoding == RotationEncoding::Quantized16) {
      std::int16_t v[4] = {};
      for (std::int16_t& x : v) (void)in.i16(x);
      q = glm::quat(float(v[3]), float(v[0]), float(v[1]), float(v[2]));
      const float norm = glm::length(q);
      q = norm > 0.0f ? q / norm : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    } else {
      (void)(in.f32(q.x) && in.f32(q.y) && in.f32(q.z) && in.f32(q.w));
    }
  }
  a.local_translations.resize(frames * translated);
  for (glm::vec3& t : a.local_translations) (void)(in.f32(t.x) && in.f32(t.y) && in.f32(t.z));
  a.root_positions.resize(frames);
  for (glm::vec3& p : a.root_positions) {
    p.y = 0.0f;
    (void)(in.f32(p.x) && in.f32(p.z));
  }
  a.root_yaws.resize(frames);
  in.f32_array(a.root_yaws);
  a.contacts.resize(frames);
  for (std::uint8_t& x : a.contacts) (void)in.u8(x);
  if (a.legacy_contacts) relabel_legacy_contacts(a);
  return {};
}

// Format 7's record of the import: where each clip's units and up axis
// came from, and why the animation section is absent.
bool has_import_record(const DatabaseParts& parts) {
  return !parts.no_animation_reason.empty() ||
         std::any_of(parts.clips.begin(), parts.clips.end(),
                     [](const Clip& clip) { return !clip.units_from.empty() || !clip.axes_from.empty(); });
}

void write_import_record(Writer& file, const DatabaseParts& parts) {
  for (const Clip& clip : parts.clips) {
    file.str(clip.units_from);
    file.str(clip.axes_from);
  }
  file.str(parts.no_animation_reason);
}

// Version 7: a presence byte, then the measured gait bands' parameters.
void write_gait_bands(Writer& file, const std::optional<GaitBandParams>& bands) {
  file.u8(bands ? 1 : 0);
  if (!bands) return;
  for (float value : {bands->walk_from_mps, bands->jog_from_mps, bands->run_from_mps, bands->hysteresis,
                      bands->smoothing_seconds, bands->transition_seconds}) {
    file.f32(value);
  }
}

}  // namespace

std::string serialize_database(const Database& database) {
  const DatabaseParts& parts = database.parts();
  // One buffer: header with a placeholder payload size, payload, checksum.
  Writer file;
  file.bytes().reserve(kDatabaseHeaderBytes + 4096 + parts.features.size() * 4 + parts.frame_flags.size() * 4);
  file.raw(std::string_view(kMagic, sizeof(kMagic)));
  // The oldest version that holds the database, so that older builds read
  // what they can: 7 with a record of the import or measured gait bands, 6 with crowd settings, else 5 with an animation section (its contact layout), else 4
  // with import units, else 3 with per-frame modifiers, else 2.
  const bool per_frame = !parts.frame_tags.empty() || !parts.frame_multiplier.empty() || !parts.frame_bias.empty();
  const bool units = std::any_of(parts.clips.begin(), parts.clips.end(),
                                 [](const Clip& clip) { return clip.metres_per_unit > 0.0f; });
  const std::uint32_t version =
      has_import_record(parts) || parts.gait_bands ? 7u : !parts.crowd_settings.empty() ? 6u : parts.animation ? 5u : units ? 4u : per_frame ? 3u : 2u;
  file.u32(version);
  file.u32(0);
  file.u64(0);
  file.str(schema_to_json(parts.schema));
  file.f32(parts.fps);
  file.u32(static_cast<std::uint32_t>(parts.normalization.size()));
  for (const DimNormalization& n : parts.normalization) {
    file.f32(n.offset);
    file.f32(n.scale);
  }
  file.u32(static_cast<std::uint32_t>(parts.tag_names.size()));
  for (const std::string& tag : parts.tag_names) file.str(tag);
  file.u32(static_cast<std::uint32_t>(parts.clips.size()));
  for (const Clip& clip : parts.clips) {
    file.str(clip.name);
    file.str(clip.source);
    file.u64(clip.tags);
    file.u8(clip.loop ? 1 : 0);
    file.u8(clip.mirrored ? 1 : 0);
    file.f32(clip.cost_multiplier);
    file.f32(clip.cost_bias);
    file.u32(clip.first_frame);
    file.u32(clip.frame_count);
  }
  file.u32(static_cast<std::uint32_t>(parts.frame_flags.size()));
  for (std::uint32_t flags : parts.frame_flags) file.u32(flags);
  file.f32_array(parts.features);
  if (version >= 3) file.u8(per_frame ? 1 : 0);
  if (per_frame) {
    // The complete per-frame values (the Database's, which fill in the clip
    // values for whichever array the parts left empty).
    for (const TagMask tags : database.frame_tags()) file.u64(tags);
    file.f32_array(database.frame_multiplier());
    file.f32_array(database.frame_bias());
  }
  if (version >= 4) file.u8(units ? 1 : 0);
  if (units) {
    for (const Clip& clip : parts.clips) file.f32(clip.metres_per_unit);
  }
  if (version >= 6) file.str(parts.crowd_settings);
  if (version >= 7) {
    write_import_record(file, parts);
    write_gait_bands(file, parts.gait_bands);
  }
  file.u8(parts.animation ? 1 : 0);
  if (parts.animation) write_animation(file, *parts.animation);

  std::string& bytes = file.bytes();
  const std::uint64_t payload_size = bytes.size() - kDatabaseHeaderBytes;
  for (int i = 0; i < 8; ++i) bytes[16 + i] = static_cast<char>((payload_size >> (8 * i)) & 0xFF);
  Hasher hasher;
  hasher.add_bytes(bytes.data(), bytes.size());
  file.u64(hasher.digest());
  return std::move(bytes);
}

namespace {

// The file's envelope: magic, version, reserved field, payload size and
// checksum. Returns the format version.
Result<std::uint32_t> check_envelope(std::string_view bytes, const std::string& source) {
  if (bytes.empty()) return make_error(source + ": truncated mmvk database (the file is empty)");
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0) {
    if (bytes.size() < sizeof(kMagic) && std::memcmp(bytes.data(), kMagic, bytes.size()) == 0) {
      return make_error(source + ": truncated mmvk database (" + std::to_string(bytes.size()) + " bytes)");
    }
    return make_error(source + ": not an mmvk database (wrong magic)");
  }
  if (bytes.size() < kDatabaseHeaderBytes + 8) {
    return make_error(source + ": truncated mmvk database (" + std::to_string(bytes.size()) + " bytes, the header and checksum need " +
                      std::to_string(kDatabaseHeaderBytes + 8) + ")");
  }
  const std::uint32_t version = read_u32_at(bytes, 8);
  if (version < 1 || version > kDatabaseFormatVersion) {
    return make_error(source + ": unsupported mmvk database version " + std::to_string(version) + " (this build reads versions 1 to " +
                      std::to_string(kDatabaseFormatVersion) + ")");
  }
  if (read_u32_at(bytes, 12) != 0) return make_error(source + ": corrupt mmvk database header (reserved field is not 0)");
  const std::uint64_t payload_size = read_u64_at(bytes, 16);
  const std::uint64_t available = bytes.size() - kDatabaseHeaderBytes - 8;
  if (payload_size > available) {
    return make_error(source + ": truncated mmvk database (" + std::to_string(bytes.size()) + " bytes, the header announces " +
                      std::to_string(payload_size) + " payload bytes but only " + std::to_string(available) + " are there)");
  }
  if (payload_size < available) {
    return make_error(source + ": corrupt mmvk database (" + std::to_string(available - payload_size) +
                      " unexpected bytes after the payload)");
  }
  Hasher hasher;
  hasher.add_bytes(bytes.data(), kDatabaseHeaderBytes + payload_size);
  if (hasher.digest() != read_u64_at(bytes, kDatabaseHeaderBytes + payload_size)) {
    return make_error(source + ": checksum mismatch: the mmvk database is corrupt");
  }
  return version;
}

// The payload, read section by section into `parts`; errors name the
// section and the byte.
class PayloadReader {
 public:
  PayloadReader(std::string_view bytes, const std::string& source, std::uint32_t version)
      : in_(bytes, kDatabaseHeaderBytes, bytes.size() - 8), source_(source), version_(version) {}

  // The schema, fps and the normalization of every dim.
  Status schema(DatabaseParts& parts) {
    std::string schema_json;
    if (!in_.str(schema_json)) return corrupt("schema");
    Result<FeatureSchema> schema = parse_schema_json(schema_json, source_ + " (schema)");
    if (!schema.ok()) return make_error(schema.message());
    parts.schema = std::move(*schema);
    if (!in_.f32(parts.fps)) return corrupt("fps");
    if (!in_.u32(dims_)) return corrupt("dims");
    if (dims_ != parts.schema.dims()) {
      return corrupt("normalization has " + std::to_string(dims_) + " dims, the schema " +
                     std::to_string(parts.schema.dims()));
    }
    if (std::uint64_t{dims_} * 8 > in_.left()) return corrupt("normalization");
    parts.normalization.resize(dims_);
    for (DimNormalization& n : parts.normalization) {
      if (!in_.f32(n.offset) || !in_.f32(n.scale)) return corrupt("normalization");
    }
    return {};
  }

  Status tags_and_clips(DatabaseParts& parts) {
    std::uint32_t tags = 0;
    if (!in_.u32(tags)) return corrupt("tag count");
    if (tags > kMaxTags) return corrupt(std::to_string(tags) + " tags");
    parts.tag_names.resize(tags);
    for (std::string& tag : parts.tag_names) {
      if (!in_.str(tag)) return corrupt("tag name");
    }
    std::uint32_t clips = 0;
    if (!in_.u32(clips)) return corrupt("clip count");
    constexpr std::size_t kMinClipBytes = 4 + 4 + 8 + 1 + 1 + 4 + 4 + 4 + 4;
    if (std::uint64_t{clips} * kMinClipBytes > in_.left()) return corrupt(std::to_string(clips) + " clips");
    parts.clips.resize(clips);
    for (Clip& clip : parts.clips) {
      std::uint8_t loop = 0;
      std::uint8_t mirrored = 0;
      if (!in_.str(clip.name) || !in_.str(clip.source) || !in_.u64(clip.tags) || !in_.u8(loop) || !in_.u8(mirrored) ||
          !in_.f32(clip.cost_multiplier) || !in_.f32(clip.cost_bias) || !in_.u32(clip.first_frame) ||
          !in_.u32(clip.frame_count)) {
        return corrupt("clip");
      }
      if (loop > 1 || mirrored > 1) return corrupt("clip flags");
      clip.loop = loop != 0;
      clip.mirrored = mirrored != 0;
    }
    return {};
  }

  // The frame flags and the feature matrix.
  Status frames(DatabaseParts& parts) {
    std::uint32_t frames = 0;
    if (!in_.u32(frames)) return corrupt("frame count");
    if (std::uint64_t{frames} * 4 > in_.left()) return corrupt(std::to_string(frames) + " frame flags");
    parts.frame_flags.resize(frames);
    for (std::uint32_t& flags : parts.frame_flags) {
      if (!in_.u32(flags)) return corrupt("frame flags");
    }
    const std::uint64_t values = std::uint64_t{frames} * dims_;
    // Version 1 ends with the features; version 2 adds a presence byte and
    // the optional animation section.
    const std::uint64_t after = version_ == 1 ? 0 : 1;
    // values > left / 4 first: values * 4 alone could wrap for a multi-GiB file.
    if (values > in_.left() / 4 || values * 4 + after > in_.left() || (version_ == 1 && values * 4 != in_.left())) {
      return corrupt("feature matrix of " + std::to_string(frames) + " x " + std::to_string(dims_) +
                     " floats needs " + std::to_string(values * 4) + " bytes, " + std::to_string(in_.left()) +
                     " are left");
    }
    parts.features.resize(values);
    in_.f32_array(parts.features);
    return {};
  }

  // The sections later versions add after the features, each behind a
  // presence byte.
  Status optional_sections(DatabaseParts& parts) {
    const auto frames = static_cast<std::uint32_t>(parts.frame_flags.size());
    if (version_ >= 3) {
      std::uint8_t per_frame = 0;
      if (!in_.u8(per_frame) || per_frame > 1) return corrupt("per-frame modifiers presence byte");
      if (per_frame) {
        if (std::uint64_t{frames} * 16 + 1 > in_.left()) {
          return corrupt("per-frame modifiers of " + std::to_string(frames) + " frames");
        }
        parts.frame_tags.resize(frames);
        for (TagMask& tags : parts.frame_tags) (void)in_.u64(tags);
        parts.frame_multiplier.resize(frames);
        in_.f32_array(parts.frame_multiplier);
        parts.frame_bias.resize(frames);
        in_.f32_array(parts.frame_bias);
      }
    }
    if (version_ >= 4) {
      std::uint8_t has_units = 0;
      if (!in_.u8(has_units) || has_units > 1) return corrupt("import units presence byte");
      if (has_units) {
        if (std::uint64_t{parts.clips.size()} * 4 + 1 > in_.left()) {
          return corrupt("import units of " + std::to_string(parts.clips.size()) + " clips");
        }
        for (Clip& clip : parts.clips) (void)in_.f32(clip.metres_per_unit);
      }
    }
    if (version_ >= 6 && !in_.str(parts.crowd_settings)) return corrupt("crowd settings");
    if (version_ >= 7) {
      for (Clip& clip : parts.clips) {
        if (!in_.str(clip.units_from) || !in_.str(clip.axes_from)) return corrupt("import record of clip '" + clip.name + "'");
      }
      if (!in_.str(parts.no_animation_reason)) return corrupt("import record's animation note");
      MMVK_TRY(read_gait_bands(parts));
    }
    if (version_ >= 2) {
      std::uint8_t has_animation = 0;
      if (!in_.u8(has_animation) || has_animation > 1) return corrupt("animation presence byte");
      if (has_animation) {
        parts.animation.emplace();
        if (std::string what = read_animation(in_, version_, *parts.animation); !what.empty()) return corrupt(what);
      } else if (in_.left() != 0) {
        return corrupt(std::to_string(in_.left()) + " bytes after the features");
      }
    }
    return {};
  }

 private:
  Status read_gait_bands(DatabaseParts& parts) {
    std::uint8_t present = 0;
    if (!in_.u8(present) || present > 1) return corrupt("gait bands presence byte");
    if (!present) return {};
    GaitBandParams& bands = parts.gait_bands.emplace();
    for (float* value : {&bands.walk_from_mps, &bands.jog_from_mps, &bands.run_from_mps, &bands.hysteresis,
                         &bands.smoothing_seconds, &bands.transition_seconds}) {
      if (!in_.f32(*value)) return corrupt("gait bands");
    }
    return {};
  }

  Error corrupt(const std::string& what) const {
    return make_error(source_ + ": corrupt mmvk database payload: " + what + " at byte " +
                      std::to_string(in_.position()));
  }

  Reader in_;
  const std::string& source_;
  const std::uint32_t version_;
  std::uint32_t dims_ = 0;
};

}  // namespace

Result<Database> deserialize_database(std::string_view bytes, std::string_view source_name) {
  const std::string source(source_name.empty() ? std::string_view("database") : source_name);
  MMVK_ASSIGN_OR_RETURN(const std::uint32_t version, check_envelope(bytes, source));
  PayloadReader payload(bytes, source, version);
  DatabaseParts parts;
  MMVK_TRY(payload.schema(parts));
  MMVK_TRY(payload.tags_and_clips(parts));
  MMVK_TRY(payload.frames(parts));
  MMVK_TRY(payload.optional_sections(parts));
  Result<Database> database = Database::create(std::move(parts));
  if (!database.ok()) return make_error(source + ": invalid mmvk database: " + database.message());
  return database;
}

Status save_database(const Database& database, const std::filesystem::path& path) {
  return write_file_atomically(path, serialize_database(database));
}

Result<Database> load_database(const std::filesystem::path& path) {
  Result<std::string> bytes = read_file(path);
  if (!bytes.ok()) return bytes.error();
  return deserialize_database(*bytes, path.string());
}

bool has_database_magic(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  char head[sizeof(kMagic)] = {};
  const bool match = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
                     ::read(fd, head, sizeof(head)) == static_cast<ssize_t>(sizeof(head)) &&
                     std::memcmp(head, kMagic, sizeof(kMagic)) == 0;
  ::close(fd);
  return match;
}

}  // namespace mmvk
