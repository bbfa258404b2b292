// assimp scene -> Motions: the skeleton's nodes, their world transforms
// sampled at one rate, converted to metres and mmvk's Y-up frame, then
// turned back into local transforms (scene_import.hpp has the rules).
#include "mmvk/import/scene_import.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <system_error>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include "import/scene_import_child.hpp"
#include "import/scene_nodes.hpp"

namespace mmvk {

namespace {

using detail::NodeTree;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// A number from the scene's metadata (FBX writes UnitScaleFactor as a float
// or a double, the axes as ints), or `fallback`.
double metadata_number(const aiScene& scene, const char* key, double fallback) {
  const aiMetadata* meta = scene.mMetaData;
  if (meta == nullptr || meta->mKeys == nullptr || meta->mValues == nullptr) return fallback;
  for (unsigned i = 0; i < meta->mNumProperties; ++i) {
    if (std::string_view(meta->mKeys[i].C_Str()) != key || meta->mValues[i].mData == nullptr) continue;
    const aiMetadataEntry& entry = meta->mValues[i];
    switch (entry.mType) {
      case AI_INT32: return *static_cast<const std::int32_t*>(entry.mData);
      case AI_UINT64: return double(*static_cast<const std::uint64_t*>(entry.mData));
      case AI_FLOAT: return *static_cast<const float*>(entry.mData);
      case AI_DOUBLE: return *static_cast<const double*>(entry.mData);
      default: return fallback;
    }
  }
  return fallback;
}

// The unit axis `axis` (0, 1, 2) times `sign`, or none when out of range.
bool signed_axis(double axis, double sign, glm::vec3& out) {
  if (!(axis == 0.0 || axis == 1.0 || axis == 2.0)) return false;
  out = glm::vec3(0.0f);
  out[int(axis)] = sign < 0.0 ? -1.0f : 1.0f;
  return true;
}

// FBX's axis set as the rotation from file coordinates to mmvk's (X right,
// Y up, Z front). A left-handed set (a mirror, which a rotation cannot hold)
// keeps its up and right axes and takes front from their cross product.
bool fbx_axes(const aiScene& scene, glm::mat3& to_mmvk) {
  glm::vec3 up, front, right;
  if (!signed_axis(metadata_number(scene, "UpAxis", -1), metadata_number(scene, "UpAxisSign", 1), up) ||
      !signed_axis(metadata_number(scene, "FrontAxis", -1), metadata_number(scene, "FrontAxisSign", 1), front) ||
      !signed_axis(metadata_number(scene, "CoordAxis", -1), metadata_number(scene, "CoordAxisSign", 1), right)) {
    return false;
  }
  if (glm::dot(glm::cross(right, up), front) < 0.5f) front = glm::cross(right, up);
  if (std::abs(glm::dot(glm::cross(right, up), front) - 1.0f) > 1e-3f) return false;  // repeated axes
  // Rows: the file's right, up and front become mmvk's X, Y and Z.
  to_mmvk = glm::transpose(glm::mat3(right, up, front));
  return true;
}

// The scale and rotation from the file's units and axes to mmvk's, and
// where they came from.
void choose_units_and_axes(const aiScene& scene, const std::string& ext, const ImportOptions& options,
                           SceneImport& out, glm::mat3& to_mmvk) {
  to_mmvk = glm::mat3(1.0f);
  if (options.metres_per_unit > 0.0f) {
    out.metres_per_unit = options.metres_per_unit;
    out.units_from = "the manifest's import.metres_per_unit";
  } else if (ext == ".fbx") {
    const double factor = metadata_number(scene, "UnitScaleFactor", 1.0);
    out.metres_per_unit = factor > 0.0 && std::isfinite(factor) ? float(factor / 100.0) : 0.01f;
    char text[80];
    std::snprintf(text, sizeof(text), "FBX UnitScaleFactor %g (centimetres per unit)", factor);
    out.units_from = text;
  } else {
    out.metres_per_unit = 1.0f;
    out.units_from = ext == ".dae" ? "COLLADA <unit> (applied by assimp)" : "glTF (metres by the format)";
  }
  if (options.up_axis_given) {
    out.axes_from = std::string("the manifest's import.up_axis \"") + (options.up_axis == UpAxis::Z ? "z" : "y") + "\"";
    if (options.up_axis == UpAxis::Z) to_mmvk = glm::mat3_cast(glm::angleAxis(-glm::half_pi<float>(), glm::vec3(1, 0, 0)));
  } else if (ext == ".fbx") {
    const bool read = fbx_axes(scene, to_mmvk);
    if (!read) to_mmvk = glm::mat3(1.0f);
    char text[120];
    std::snprintf(text, sizeof(text), "FBX UpAxis %g (0 = X, 1 = Y, 2 = Z), UpAxisSign %g",
                  metadata_number(scene, "UpAxis", 1), metadata_number(scene, "UpAxisSign", 1));
    out.axes_from = read ? std::string(text) : "FBX without a valid axis set (Y-up assumed)";
  } else {
    out.axes_from = ext == ".dae" ? "COLLADA <up_axis> (applied by assimp)" : "glTF (Y-up by the format)";
  }
}

// The sampling rate when the caller gives none (scene_import.hpp).
float key_rate(const aiAnimation& animation) {
  const double ticks = animation.mTicksPerSecond > 0.0 ? animation.mTicksPerSecond : 25.0;  // assimp's default
  double smallest = 0.0;
  auto visit = [&](double a, double b) {
    const double step = (b - a) / ticks;
    if (step >= 1.0 / kMaxFps && std::isfinite(step) && (smallest == 0.0 || step < smallest)) smallest = step;
  };
  for (unsigned c = 0; animation.mChannels != nullptr && c < animation.mNumChannels; ++c) {
    if (animation.mChannels[c] == nullptr) continue;
    const aiNodeAnim& channel = *animation.mChannels[c];
    for (unsigned k = 1; channel.mPositionKeys != nullptr && k < channel.mNumPositionKeys; ++k) {
      visit(channel.mPositionKeys[k - 1].mTime, channel.mPositionKeys[k].mTime);
    }
    for (unsigned k = 1; channel.mRotationKeys != nullptr && k < channel.mNumRotationKeys; ++k) {
      visit(channel.mRotationKeys[k - 1].mTime, channel.mRotationKeys[k].mTime);
    }
  }
  if (smallest == 0.0) return 30.0f;
  double fps = 1.0 / smallest;
  if (const double rounded = std::round(fps); std::abs(fps - rounded) <= 0.005 * fps) fps = rounded;
  return float(std::clamp(fps, double(kMinFps), 120.0));
}

std::string animation_label(const aiAnimation& animation, unsigned index) {
  const std::string name = animation.mName.C_Str();
  return name.empty() ? "animation " + std::to_string(index) + " (unnamed)" : "animation '" + name + "'";
}

// One animation sampled into a Motion over the tree's joints.
Result<Motion> sample_animation(const NodeTree& tree, const aiAnimation& animation, float fps,
                                std::uint64_t max_samples, const std::string& where) {
  const double ticks = animation.mTicksPerSecond > 0.0 ? animation.mTicksPerSecond : 25.0;
  const double duration = animation.mDuration / ticks;
  if (!(duration >= 0.0) || !std::isfinite(duration)) return make_error(where + ": its duration is not finite and >= 0");
  const double frames = std::round(duration * fps) + 1.0;
  if (frames * double(tree.joints.size()) > double(max_samples)) {
    char text[200];
    std::snprintf(text, sizeof(text), ": %.6g s at %g fps is %.6g frames of %zu joints, over the limit of %llu samples",
                  duration, double(fps), frames, tree.joints.size(), static_cast<unsigned long long>(max_samples));
    return make_error(where + text);
  }
  Motion motion;
  motion.skeleton = tree.skeleton;
  motion.fps = fps;
  motion.frame_count = static_cast<std::uint32_t>(frames);
  motion.local_positions.resize(std::size_t{motion.frame_count} * tree.joints.size());
  motion.local_rotations.resize(std::size_t{motion.frame_count} * tree.joints.size());
  const std::vector<const aiNodeAnim*> channels = detail::channels_by_node(tree, animation);
  std::vector<detail::JointPose> world(tree.joints.size());
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    const double time = std::min(double(f) / fps, duration) * ticks;
    MMVK_TRY(detail::joint_world_poses(tree, channels, time, world, where));
    detail::store_local_pose(tree, world, f, motion);
  }
  return motion;
}

Result<SceneImport> import_loaded(const aiScene* scene, const std::string& ext, const std::string& source,
                                  const SceneImportOptions& options, const char* assimp_error) {
  if (scene == nullptr || scene->mRootNode == nullptr) {
    return make_error(source + ": assimp could not read it: " + std::string(assimp_error));
  }
  if (scene->mNumAnimations == 0 || scene->mAnimations == nullptr) {
    return make_error(source + ": no animation in the file (a model without motion?)");
  }
  if (!(options.fps == 0.0f || (options.fps >= kMinFps && options.fps <= kMaxFps))) {
    return make_error(source + ": fps " + std::to_string(options.fps) + " is outside the supported range");
  }
  SceneImport out;
  glm::mat3 to_mmvk;
  choose_units_and_axes(*scene, ext, options.import, out, to_mmvk);
  std::vector<std::string> names;
  for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
    if (scene->mAnimations[a] == nullptr) continue;
    const aiAnimation& animation = *scene->mAnimations[a];
    names.push_back("'" + std::string(animation.mName.C_Str()) + "'");
    if (!options.animation.empty() && options.animation != animation.mName.C_Str()) continue;
    const std::string where = source + ": " + animation_label(animation, a);
    MMVK_ASSIGN_OR_RETURN(NodeTree tree,
                          detail::build_node_tree(*scene, &animation, to_mmvk, out.metres_per_unit, where));
    const float fps = options.fps > 0.0f ? options.fps : key_rate(animation);
    MMVK_ASSIGN_OR_RETURN(Motion motion, sample_animation(tree, animation, fps, options.max_samples, where));
    out.animations.push_back({animation.mName.C_Str(), std::move(motion)});
  }
  if (out.animations.empty()) {
    std::string list;
    for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
    return make_error(source + ": no animation named '" + options.animation + "'; the file has " + list);
  }
  return out;
}

// The reading setup shared by files and memory: FBX pivots collapsed into
// their nodes (else assimp adds "$AssimpFbx$" helper nodes to the
// skeleton), and assimp's own validation of what it built, which turns
// dangling indices in a hostile file into an error instead of a crash here.
void configure(Assimp::Importer& importer) {
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_MATERIALS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_CAMERAS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_LIGHTS, false);
}

constexpr unsigned kPostProcess = aiProcess_ValidateDataStructure;

// assimp's read of a checked file, in this process.
Result<SceneImport> read_scene_here(const std::filesystem::path& path, const SceneImportOptions& options) {
  const std::string source = path.string();
  Assimp::Importer importer;
  configure(importer);
  const aiScene* scene = importer.ReadFile(source, kPostProcess);
  return import_loaded(scene, lower_extension(path), source, options, importer.GetErrorString());
}

}  // namespace

bool is_scene_path(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".fbx" || ext == ".gltf" || ext == ".glb" || ext == ".dae";
}

Result<SceneImport> import_scene(const std::filesystem::path& path, const SceneImportOptions& options) {
  const std::string source = path.string();
  if (!is_scene_path(path)) return make_error(source + ": not an FBX, glTF or COLLADA file name (.fbx, .gltf, .glb, .dae)");
  std::error_code error;
  // assimp opens the file itself (a .gltf names its buffers beside it), so
  // the checks that read_file() makes come first: a FIFO would block it.
  if (!std::filesystem::is_regular_file(path, error)) {
    return make_error(source + (std::filesystem::exists(path, error) ? ": not a regular file" : ": no such file"));
  }
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > kMaxSceneFileBytes) {
    return make_error(source + ": larger than the limit of " + std::to_string(kMaxSceneFileBytes) + " bytes");
  }
  return options.isolate ? detail::read_scene_in_child(path, options, read_scene_here) : read_scene_here(path, options);
}

Result<SceneImport> import_assimp_scene(const aiScene& scene, std::string_view format, std::string_view source,
                                        const SceneImportOptions& options) {
  std::string ext(format);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return import_loaded(&scene, ext, std::string(source), options, "no root node");
}

Result<SceneImport> import_scene_from_memory(std::span<const std::uint8_t> bytes, std::string_view extension,
                                             std::string_view source, const SceneImportOptions& options) {
  const std::string name(source);
  std::string ext(extension);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (!(ext == ".fbx" || ext == ".gltf" || ext == ".glb" || ext == ".dae")) return make_error(name + ": not an FBX, glTF or COLLADA extension: " + std::string(extension));
  if (bytes.empty()) return make_error(name + ": empty");
  if (bytes.size() > kMaxSceneFileBytes) return make_error(name + ": larger than the limit");
  Assimp::Importer importer;
  configure(importer);
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), kPostProcess, ext.c_str() + 1);
  return import_loaded(scene, ext, name, options, importer.GetErrorString());
}

}  // namespace mmvk
