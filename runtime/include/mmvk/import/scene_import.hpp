// FBX, glTF 2.0 (.gltf/.glb) and COLLADA (.dae) through assimp: each of a
// file's animations becomes a Motion like motion_from_bvh()'s (local joint
// transforms in metres, Y-up), sampled at one rate, so that everything after
// the import (features, database, mirror, resample) is the same as for BVH.
//
// What is read:
//   - The skeleton: the nodes of the skin's joints (the bones of every mesh)
//     and their ancestors below the scene's root node; without a skin, the
//     nodes the animation moves and their ancestors. Joints keep the file's
//     node names and depth-first order. Transforms of nodes above the
//     skeleton (an FBX "Armature", COLLADA's unit and up-axis fix-up that
//     assimp puts in the root node) are baked into the root joint.
//   - The motion: each joint's world transform at time k / fps (k = 0 ..
//     round(duration x fps)), from the animation's position, rotation and
//     scaling keys (linear, slerp, linear; clamped outside the keys) and
//     the static transforms of nodes without keys. Scale in a node moves its
//     descendants but is not kept in the joints' rotations (mmvk poses have
//     none), so world positions are exact and rotations are the
//     orthonormalized node frames.
//   - Units: the manifest's metres_per_unit when > 0; else the file's: FBX
//     UnitScaleFactor (centimetres per unit, so metres_per_unit =
//     UnitScaleFactor / 100), glTF metres (the format's rule), COLLADA
//     <unit meter> (assimp applies it in the root node, so 1 here).
//   - Up axis: the manifest's "up_axis" when it gives one; else the file's:
//     FBX UpAxis/FrontAxis/CoordAxis with their signs (mapped onto mmvk's
//     X right, Y up, Z front; a left-handed set keeps only its up axis),
//     glTF Y-up, COLLADA <up_axis> (applied by assimp).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

struct aiScene;

namespace mmvk {

// Whether `path` names a file import_scene() reads, by its extension (any
// case): .fbx, .gltf, .glb or .dae.
bool is_scene_path(const std::filesystem::path& path);

// The largest scene file read (bytes), and the most samples (frames x
// joints) one animation may produce: a hostile duration or rate is an error,
// not an allocation.
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t{1} << 30;
// (2^25 samples is 0.9 GB of local transforms.)
inline constexpr std::uint64_t kMaxSceneSamples = std::uint64_t{1} << 25;

struct SceneImportOptions {
  // metres_per_unit > 0 overrides the file's units; up_axis_given makes
  // up_axis override the file's axes (the manifest's "import" fields).
  ImportOptions import;
  // Samples per second of every animation; 0 = the file's key rate: one over
  // the smallest interval between two keys of a channel, snapped to an
  // integer within 0.5%, clamped to [kMinFps, 120]; 30 with no such interval.
  float fps = 0.0f;
  // Only the animation of this name; empty = every animation in the file.
  std::string animation;
  // The most samples (frames x joints) of one animation; more is an error.
  std::uint64_t max_samples = kMaxSceneSamples;
  // import_scene() runs assimp in a child process (fork), so that a damaged
  // file on which assimp crashes, hangs or allocates without bound ends in
  // an error naming the file instead of ending the caller; false reads it in
  // this process (an application that must not fork).
  bool isolate = true;
  // With isolate: the child's time limit (seconds), and the address space it
  // may map beyond what the process maps when it starts (not enforced in an
  // AddressSanitizer build, whose shadow memory a limit would refuse).
  double timeout_seconds = 600.0;
  std::uint64_t memory_budget_bytes = std::uint64_t{8} << 30;
};

struct SceneAnimation {
  std::string name;  // the animation's name in the file (may be empty)
  Motion motion;
};

struct SceneImport {
  std::vector<SceneAnimation> animations;  // in the file's order
  float metres_per_unit = 1.0f;            // the scale applied
  std::string units_from;                  // where it came from, for messages ("FBX UnitScaleFactor 1")
  std::string axes_from;                   // where the up axis came from ("glTF (Y-up by the format)")
};

// Reads the file with assimp. Errors name the file, and the animation where
// one is at fault: not a regular file or over kMaxSceneFileBytes, assimp's
// own parse error, no animation (or none named options.animation, listing
// the names), no skeleton, a key or transform that is not finite, too many
// samples; with options.isolate, assimp crashing, or running past the time
// or memory limit.
Result<SceneImport> import_scene(const std::filesystem::path& path, const SceneImportOptions& options);

// A scene the caller has read with assimp itself (an application that
// already uses it): `format` (".fbx", ".gltf", ".glb", ".dae") says which
// metadata rules apply (scene_import.hpp's units and axes); `source` names
// it in messages. The scene is only read. tests/fuzz/fuzz_scene_import.cpp
// feeds it scenes built from fuzz bytes.
Result<SceneImport> import_assimp_scene(const aiScene& scene, std::string_view format, std::string_view source,
                                        const SceneImportOptions& options);

// The same from bytes in memory: `extension` (".fbx",
// ".glb", ...) picks the format as the file name would; `source` names it in
// messages. A .gltf whose buffers are separate files cannot be read this way.
Result<SceneImport> import_scene_from_memory(std::span<const std::uint8_t> bytes, std::string_view extension,
                                             std::string_view source, const SceneImportOptions& options);

}  // namespace mmvk
