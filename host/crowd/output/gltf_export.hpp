// `mmvk crowd --gltf FILE.glb` and mmvk.Crowd.write_gltf: the recorded
// characters (pose_recording.hpp) in one glTF 2.0 binary (.glb).
//
// Per character, a node "agent_0000" (its root: translation on the ground,
// rotation R_y(yaw)) over one node per joint of the database's skeleton
// (named as the skeleton names them; translation the rest offset, or the
// translated joint's own), and a skin over those joint nodes (skeleton: the
// agent node; inverse bind matrices of the rest pose, every rotation the
// identity). One animation, "crowd", samples at the tick rate (times i /
// rate seconds, sample i the pose after the i-th recorded tick), LINEAR:
// each agent node's translation and rotation, each joint node's rotation
// (x, y, z, w, unit, each sample on the same side as the one before so
// interpolation takes the short arc) and each translated joint's
// translation. glTF's units and axes are mmvk's: metres, +Y up, +Z forward.
// There is no mesh: the skins are for binding a character's own.
#pragma once

#include <filesystem>
#include <string>

#include "mmvk/common/status.hpp"
#include "output/pose_recording.hpp"

namespace mmvk::crowd {

// The .glb file's bytes. Errors: no ticks recorded.
Result<std::string> glb_bytes(const PoseRecording& recording);

// Before the run: `path` ends in .glb and can be written. Errors name `option`.
Status check_gltf_path(const std::filesystem::path& path, const std::string& option);

// The file, atomically. Errors name it.
Status write_gltf(const PoseRecording& recording, const std::filesystem::path& path);

}  // namespace mmvk::crowd
