// libFuzzer target: mmvk's side of the FBX/glTF/COLLADA import on scenes
// built from the fuzz bytes (import_assimp_scene: skeleton from bones or
// channels, key sampling, units and axes from metadata, the build's
// plausibility measures). Node trees with repeated or missing names, any
// float in transforms and keys (NaN, inf, out of order), empty key arrays,
// huge durations and odd metadata must end in a Result, never a crash, a
// sanitizer report or a hang.
//
// Why not assimp's parsers: Debian's assimp 5.2.5 is not instrumented, and
// fed mutated testmodel files it fails within seconds in its own code (a
// heap-buffer-overflow in the glTF 2 reader, an abort in the COLLADA
// reader, a 3.6 GB allocation in the binary FBX reader; docs/fuzzing.md),
// findings that would end every run and that mmvk cannot fix. assimp's
// parsers are fuzzed upstream (OSS-Fuzz).
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <assimp/scene.h>

#include "mmvk/import/import_check.hpp"
#include "mmvk/import/scene_import.hpp"

namespace {

// The fuzz bytes as a stream of small decisions; zeros once spent.
struct Bytes {
  const std::uint8_t* data;
  std::size_t size;
  std::uint8_t byte() { return size > 0 ? (--size, *data++) : 0; }
  float number() {
    // Mostly small values (whole transforms), sometimes any bit pattern.
    if (byte() % 4 != 0) return float(int(byte()) - 128) / 16.0f;
    std::uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) bits = bits << 8 | byte();
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  aiString name() { return aiString(std::string("n") + std::to_string(byte() % 12)); }
};

aiNode* make_tree(Bytes& in) {
  const unsigned count = 1 + in.byte() % 24;
  std::vector<aiNode*> nodes;
  std::vector<std::vector<aiNode*>> children(count);
  for (unsigned i = 0; i < count; ++i) {
    nodes.push_back(new aiNode());
    nodes[i]->mName = in.name();
    for (unsigned e = 0; e < 16 && in.byte() % 3 == 0; ++e) (&nodes[i]->mTransformation.a1)[e] = in.number();
    if (i > 0) children[in.byte() % i].push_back(nodes[i]);
  }
  for (unsigned i = 0; i < count; ++i) {
    if (children[i].empty()) continue;
    nodes[i]->mNumChildren = unsigned(children[i].size());
    nodes[i]->mChildren = new aiNode*[children[i].size()];
    for (std::size_t c = 0; c < children[i].size(); ++c) {
      nodes[i]->mChildren[c] = children[i][c];
      children[i][c]->mParent = nodes[i];
    }
  }
  return nodes[0];
}

template <typename Key, typename Fill>
Key* make_keys(Bytes& in, unsigned& count, Fill fill) {
  count = in.byte() % 6;
  if (count == 0) return nullptr;
  Key* keys = new Key[count];
  double time = 0.0;
  for (unsigned k = 0; k < count; ++k) {
    time += in.byte() % 8 == 0 ? double(in.number()) : double(in.byte() % 5);
    keys[k].mTime = time;
    fill(keys[k]);
  }
  return keys;
}

aiAnimation* make_animation(Bytes& in) {
  auto* animation = new aiAnimation();
  animation->mName = in.name();
  animation->mDuration = in.byte() % 4 == 0 ? double(in.number()) : double(in.byte() % 30);
  animation->mTicksPerSecond = in.byte() % 4 == 0 ? double(in.number()) : double(in.byte() % 60);
  animation->mNumChannels = 1 + in.byte() % 6;
  animation->mChannels = new aiNodeAnim*[animation->mNumChannels];
  for (unsigned c = 0; c < animation->mNumChannels; ++c) {
    auto* channel = animation->mChannels[c] = new aiNodeAnim();
    channel->mNodeName = in.name();
    auto vector = [&](aiVectorKey& key) { key.mValue = aiVector3D(in.number(), in.number(), in.number()); };
    channel->mPositionKeys = make_keys<aiVectorKey>(in, channel->mNumPositionKeys, vector);
    channel->mRotationKeys = make_keys<aiQuatKey>(in, channel->mNumRotationKeys, [&](aiQuatKey& key) {
      key.mValue = aiQuaternion(in.number(), in.number(), in.number(), in.number());
    });
    channel->mScalingKeys = make_keys<aiVectorKey>(in, channel->mNumScalingKeys, vector);
  }
  return animation;
}

// A skin: one mesh whose bones name nodes (or none).
void add_skin(Bytes& in, aiScene& scene) {
  const unsigned bones = in.byte() % 4;
  if (bones == 0) return;
  scene.mNumMeshes = 1;
  scene.mMeshes = new aiMesh*[1];
  scene.mMeshes[0] = new aiMesh();
  scene.mMeshes[0]->mNumBones = bones;
  scene.mMeshes[0]->mBones = new aiBone*[bones];
  for (unsigned b = 0; b < bones; ++b) {
    scene.mMeshes[0]->mBones[b] = new aiBone();
    scene.mMeshes[0]->mBones[b]->mName = in.name();
  }
}

void add_metadata(Bytes& in, aiScene& scene) {
  if (in.byte() % 2 == 0) return;
  scene.mMetaData = aiMetadata::Alloc(4);
  scene.mMetaData->Set(0, "UnitScaleFactor", in.number());
  scene.mMetaData->Set(1, "UpAxis", std::int32_t(in.byte() % 4) - 1);
  scene.mMetaData->Set(2, "FrontAxis", std::int32_t(in.byte() % 4) - 1);
  scene.mMetaData->Set(3, "CoordAxis", std::int32_t(in.byte() % 4) - 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return 0;
  Bytes in{data, size};
  static constexpr const char* kFormats[] = {".fbx", ".gltf", ".glb", ".dae"};
  const char* format = kFormats[in.byte() % 4];
  aiScene scene;  // its destructor frees what is built here
  scene.mRootNode = make_tree(in);
  add_skin(in, scene);
  add_metadata(in, scene);
  scene.mNumAnimations = 1 + in.byte() % 2;
  scene.mAnimations = new aiAnimation*[scene.mNumAnimations];
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) scene.mAnimations[a] = make_animation(in);
  mmvk::SceneImportOptions options;
  options.fps = in.byte() % 2 == 0 ? 0.0f : 30.0f;  // 0: the keys' own rate
  options.max_samples = 1 << 16;                    // a claimed hour-long animation is an error, not a slow run
  mmvk::Result<mmvk::SceneImport> imported = mmvk::import_assimp_scene(scene, format, "fuzz", options);
  if (!imported.ok()) return 0;
  for (const mmvk::SceneAnimation& animation : imported->animations) (void)mmvk::measure_import(animation.motion);
  return 0;
}
