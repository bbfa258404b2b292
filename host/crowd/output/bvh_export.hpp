// `mmvk crowd --bvh DIR` and mmvk.Crowd.write_bvh: one BVH file per recorded
// character (pose_recording.hpp), DIR/agent_0000.bvh, ... , on the
// database's skeleton at the tick rate (Frame Time 1 / rate; frame i is the
// pose after the i-th recorded tick).
//
// The file, as mmvk's own BVH reader (and CMU's, Blender's) reads it:
// centimetres, +Y up; rotations "Zrotation Xrotation Yrotation" in degrees
// (intrinsic, R = Rz * Rx * Ry); the skeleton's roots and its translated
// joints (the hips) have position channels before them, the others rotations
// only. A root carries the character's root transform: its position channels
// are root + R_y(yaw) * its translation, its rotation R_y(yaw) * its local
// rotation, so the file shows the character where the crowd showed it. Each
// joint's OFFSET is its rest offset; a leaf's End Site continues its bone by
// half its offset (2 cm up for a bone of no length), which places no joint.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mmvk/common/status.hpp"
#include "output/pose_recording.hpp"

namespace mmvk::crowd {

// The files for `agents` characters in `dir`: agent_0000.bvh, ... (wider
// numbers past 9,999).
std::vector<std::filesystem::path> bvh_paths(const std::filesystem::path& dir, std::uint32_t agents);

// Before the run, making nothing: `dir` is a folder where every file
// bvh_paths names can be written, or it does not exist yet and can be made
// (its parent is a writable folder; write_bvh_files makes it). Errors name
// `option`: `dir` a file or a link to nothing, a missing or unwritable
// parent, a file that cannot be replaced.
Status check_bvh_folder(const std::filesystem::path& dir, std::uint32_t agents, const std::string& option);

// Character `agent`'s BVH text. Errors: no ticks recorded, a skeleton whose
// joints are not in parent-before-child order.
Result<std::string> bvh_text(const PoseRecording& recording, std::uint32_t agent);

// Every recorded character's file into `dir`, each atomically; `dir` is
// made (not its parents) when missing, just before its first file. Errors
// name the folder or the file.
Status write_bvh_files(const PoseRecording& recording, const std::filesystem::path& dir);

}  // namespace mmvk::crowd
