// BVH parsing: text -> hierarchy + raw channel values, exactly as written in
// the file (no unit conversion, no kinematics). See motion.hpp for turning a
// BvhFile into local joint transforms in metres.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/common/status.hpp"

namespace mmvk {

enum class BvhChannel : std::uint8_t { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };

struct BvhJoint {
  std::string name;
  int parent = -1;                     // index into BvhFile::joints; -1 for the root
  glm::vec3 offset{0.0f};              // OFFSET, in file units
  std::vector<BvhChannel> channels;    // in file order
  int first_channel = 0;               // column of channels[0] in a motion line
  bool has_end_site = false;
  glm::vec3 end_site_offset{0.0f};     // OFFSET of the End Site, if any
};

struct BvhFile {
  std::string source;                  // file name used in error messages
  std::vector<BvhJoint> joints;        // depth-first file order: parent index < child index
  int channel_count = 0;               // values per motion line
  int frame_count = 0;
  double frame_time = 0.0;             // seconds per frame, > 0
  std::vector<float> values;           // [frame_count x channel_count], degrees and file units
};

struct BvhParseOptions {
  // When true (the default), the number of non-empty motion lines must equal
  // "Frames:". When false, a different count is accepted and frame_count
  // becomes the number of lines read (Debian's assimp sample Boxing_Toes.bvh
  // claims 3069 frames and holds 3070). Every line must still be complete.
  bool strict_frame_count = true;
};

// Parses BVH text. `source` names the file in error messages, which also give
// the 1-based line number ("walk.bvh:12: expected '{' after ROOT Hips").
// Accepted: CR, LF, CRLF and mixed line endings; any blanks (spaces, TABs) as
// separators; numbers as strtod reads them (".0083333", "-2.47e-15", but not
// inf/nan); keywords in any case; 0 to 6 channels per joint; "Frames: 0".
// Rejected, with the line: a missing or extra brace, a missing OFFSET, an
// unknown or repeated channel, a CHANNELS count that disagrees with its list,
// a missing MOTION/Frames:/Frame Time:, a frame time <= 0, a motion line with
// too few or too many values or a non-numeric token, and (when strict) more
// or fewer motion lines than Frames:. Memory is reserved from the text's size,
// never from the Frames: claim alone.
Result<BvhFile> parse_bvh(std::string_view text, std::string_view source);
Result<BvhFile> parse_bvh(std::string_view text, std::string_view source, const BvhParseOptions& options);
Result<BvhFile> load_bvh(const std::filesystem::path& path);
Result<BvhFile> load_bvh(const std::filesystem::path& path, const BvhParseOptions& options);

}  // namespace mmvk
