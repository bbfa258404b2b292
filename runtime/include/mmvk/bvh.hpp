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

#include "mmvk/status.hpp"

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

// Parses BVH text. `source` names the file in error messages, which also give
// the 1-based line number ("walk.bvh:12: expected '{' after ROOT Hips").
Result<BvhFile> parse_bvh(std::string_view text, std::string_view source);
Result<BvhFile> load_bvh(const std::filesystem::path& path);

}  // namespace mmvk
