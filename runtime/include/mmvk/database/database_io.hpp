// The .mmdb file: a versioned, checksummed binary form of a Database.
//
// Layout (all integers and floats little-endian):
//   offset 0   8 bytes  magic "MMVKDB\n\0"
//          8   u32      format version (kDatabaseFormatVersion)
//         12   u32      reserved, 0
//         16   u64      payload size P in bytes
//         24   P bytes  payload:
//                         str  schema as JSON (schema_to_json)
//                         f32  fps
//                         u32  dims, then dims x (f32 offset, f32 scale)
//                         u32  tag count, then that many str
//                         u32  clip count, then per clip: str name, str source,
//                              u64 tags, u8 loop, u8 mirrored, f32 cost multiplier,
//                              f32 cost bias, u32 first frame, u32 frame count
//                         u32  frames, then frames x u32 frame flags
//                         f32  features [frames x dims], row-major, normalized
//                         u8   1 when per-frame modifiers follow, else 0 (version 3
//                              on; version 3 is written only for a database that has them):
//                              u64 tags [frames], f32 cost multiplier [frames],
//                              f32 cost bias [frames] (the manifest's tag_ranges
//                              and cost_ranges; without them the clips' values hold)
//                         u8   1 when the clips' import units follow, else 0
//                              (version 4 on; version 4 is written only for a
//                              database that records them and has no animation):
//                              f32 metres per file unit [clips]
//                         str  the crowd settings (DatabaseParts::crowd_settings;
//                              version 6 on; version 6 is written only for a
//                              database that has them)
//                         u8   1 when the gait bands follow, else 0 (version 7
//                              on): f32 walk_from, jog_from, run_from (m/s),
//                              hysteresis, smoothing seconds, transition seconds
//                         u8   1 when the animation section follows, else 0 (version 2)
//                         the animation section (version 2, animation_data.hpp):
//                              u32 joints, then per joint: str name, i32 parent,
//                              f32 x3 rest offset, i32 mirror partner;
//                              u32 T, then T x u32 translated joints;
//                              the contact setup (foot_contacts.hpp), version 5:
//                                i32 left, right contact joint (toe), i32 left,
//                                right heel joint, str left toe, right toe, left
//                                heel, right heel bone, f32 enter height, exit
//                                height, enter speed, exit speed, min contact
//                                seconds, min gap seconds, speed step seconds,
//                                floor percentile, heel height extra, u8 height
//                                above clip floor;
//                              versions 2 to 4:
//                                i32 left, i32 right contact joint, str left bone,
//                                str right bone, f32 max height, f32 max speed,
//                                f32 ankle height extra, u8 height above clip
//                                floor, f32 floor percentile;
//                              u8 rotation encoding (0 float32, 1 quantized16);
//                              u32 frames, then rotations [frames x joints]
//                              (x, y, z, w as f32, or as i16 / 32767 with w >= 0),
//                              f32 x3 translations [frames x T],
//                              f32 x2 root (x, z) [frames], f32 root yaw [frames],
//                              u8 contacts [frames] (FootContact bits; versions 2
//                              to 4 have the planted bits alone)
//                       (str = u32 byte length + UTF-8 bytes)
//   24 + P     u64      FNV-1a 64 of bytes [0, 24 + P)
// Loading checks, in order: the length covers the header, the magic, the
// version, that the payload size matches the file length exactly, the
// checksum, then every size inside the payload against what is left, and
// finally everything Database::create validates. Each failure names the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// Version 2 adds the optional animation section, version 3 the per-frame
// tags and cost modifiers, version 4 the clips' import units, version 5 the
// contact labels of foot_contacts.hpp (toe and heel bits, hysteresis and
// minimum durations on horizontal speed), version 6 the manifest's crowd
// settings, version 7 the record of the import (each clip's units_from and
// axes_from, the no_animation_reason) and the measured gait bands
// (gait_bands.hpp). A file gets the oldest version that holds it: 7 with an
// import record or gait bands, else 6 with crowd settings, else 5 with
// animation, else 4 with import units, else 3 with per-frame modifiers, else
// 2. Versions 1 to 6 still load (version 1: features only,
// Database::animation() null; before 4: Clip::metres_per_unit 0; before 5:
// the planted bits gain the bit of the point they were detected on, and
// AnimationData::legacy_contacts is set; before 7: no import record and no
// gait bands).
inline constexpr std::uint32_t kDatabaseFormatVersion = 7;
inline constexpr std::size_t kDatabaseHeaderBytes = 24;

// The file's bytes.
std::string serialize_database(const Database& database);
// Parses and validates file bytes; `source` names the file in messages.
Result<Database> deserialize_database(std::string_view bytes, std::string_view source);

// Atomic write (temp file beside the target, fsync, rename): a failed save
// leaves any previous file intact.
Status save_database(const Database& database, const std::filesystem::path& path);
Result<Database> load_database(const std::filesystem::path& path);
// True when `path` is a regular file that begins with the magic: hosts that
// take a database or a manifest tell them apart by content as well as by
// the .mmdb extension (a database named db.bin was read as JSON: "a NUL
// byte at offset 7"). Never blocks (a FIFO is no database).
bool has_database_magic(const std::filesystem::path& path);

}  // namespace mmvk
