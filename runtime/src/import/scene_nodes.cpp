// An assimp node tree as mmvk's skeleton, and its joints' world transforms
// at a time: keys interpolated as assimp's own evaluator does (linear
// positions and scales, slerped rotations, held outside the keys).
#include "import/scene_nodes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string_view>

#include <assimp/scene.h>

namespace mmvk::detail {

namespace {

// Nodes depth-first (parents before children), without recursion: a hostile
// file's tree may be deeper than the stack.
Status flatten(const aiNode* root, NodeTree& tree, const std::string& where) {
  std::vector<std::pair<const aiNode*, int>> stack{{root, -1}};
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    if (tree.nodes.size() == kMaxSceneNodes) {
      return make_error(where + ": more than " + std::to_string(kMaxSceneNodes) + " nodes in the scene");
    }
    const int index = static_cast<int>(tree.nodes.size());
    tree.nodes.push_back(node);
    tree.node_parent.push_back(parent);
    for (unsigned c = node->mChildren != nullptr ? node->mNumChildren : 0; c-- > 0;) {
      if (node->mChildren[c] != nullptr) stack.push_back({node->mChildren[c], index});
    }
  }
  return {};
}

// Node index by name (the first node of a name: names are how assimp ties
// bones and channels to nodes).
std::map<std::string_view, int> nodes_by_name(const NodeTree& tree) {
  std::map<std::string_view, int> names;
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    names.emplace(std::string_view(tree.nodes[i]->mName.C_Str()), static_cast<int>(i));
  }
  return names;
}

// Which nodes are joints: the skin's bones, else the animated nodes; then
// their ancestors below the root node, and the root node when the joints
// would otherwise have several tops.
std::vector<bool> joint_marks(const aiScene& scene, const aiAnimation* animation, const NodeTree& tree) {
  const std::map<std::string_view, int> names = nodes_by_name(tree);
  std::vector<bool> marked(tree.nodes.size(), false);
  bool any = false;
  auto mark = [&](const aiString& name) {
    const auto it = names.find(std::string_view(name.C_Str()));
    if (it != names.end()) any = marked[std::size_t(it->second)] = true;
  };
  // Counts are checked against null arrays: a scene an application built
  // (import_assimp_scene) has not been through assimp's validation.
  for (unsigned m = 0; scene.mMeshes != nullptr && m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    for (unsigned b = 0; mesh != nullptr && mesh->mBones != nullptr && b < mesh->mNumBones; ++b) {
      if (mesh->mBones[b] != nullptr) mark(mesh->mBones[b]->mName);
    }
  }
  const bool skinned = any;
  for (unsigned c = 0; !skinned && animation != nullptr && animation->mChannels != nullptr && c < animation->mNumChannels;
       ++c) {
    if (animation->mChannels[c] != nullptr) mark(animation->mChannels[c]->mNodeName);
  }
  // Children come after parents, so one backward pass closes over ancestors.
  for (std::size_t i = tree.nodes.size(); i-- > 1;) {
    if (marked[i] && tree.node_parent[i] > 0) marked[std::size_t(tree.node_parent[i])] = true;
  }
  std::size_t tops = 0;
  for (std::size_t i = 1; i < tree.nodes.size(); ++i) tops += marked[i] && tree.node_parent[i] == 0 ? 1 : 0;
  if (tops > 1) marked[0] = true;
  return marked;
}

// The node's local transform at `ticks` from its channel; components a
// channel has no keys for keep the node's static transform.
aiMatrix4x4 sample_channel(const aiNode& node, const aiNodeAnim& channel, double ticks) {
  aiVector3D scaling, position;
  aiQuaternion rotation;
  node.mTransformation.Decompose(scaling, rotation, position);
  auto find = [ticks](const auto* keys, unsigned count, auto& value, auto&& blend) {
    if (count == 0 || keys == nullptr) return;
    const auto* end = keys + count;
    const auto* next = std::upper_bound(keys, end, ticks, [](double t, const auto& key) { return t < key.mTime; });
    if (next == keys) {
      value = keys[0].mValue;
    } else if (next == end) {
      value = keys[count - 1].mValue;
    } else {
      const auto& before = next[-1];
      const double span = next->mTime - before.mTime;
      // Clamped: keys a hostile file wrote out of order put `ticks` outside
      // the pair, and a double beyond float's range does not convert.
      const float factor = span > 0.0 ? static_cast<float>(std::clamp((ticks - before.mTime) / span, 0.0, 1.0)) : 0.0f;
      blend(value, before.mValue, next->mValue, factor);
    }
  };
  auto lerp = [](aiVector3D& out, const aiVector3D& a, const aiVector3D& b, float t) { out = a + (b - a) * t; };
  auto slerp = [](aiQuaternion& out, const aiQuaternion& a, const aiQuaternion& b, float t) {
    aiQuaternion::Interpolate(out, a, b, t);
  };
  find(channel.mPositionKeys, channel.mNumPositionKeys, position, lerp);
  find(channel.mRotationKeys, channel.mNumRotationKeys, rotation, slerp);
  find(channel.mScalingKeys, channel.mNumScalingKeys, scaling, lerp);
  return aiMatrix4x4(scaling, rotation.Normalize(), position);
}

// A node's world matrix as a pose in mmvk's frame: the translation scaled
// to metres, the frame's axes orthonormalized (scale and shear dropped).
JointPose to_pose(const aiMatrix4x4& m, const NodeTree& tree) {
  JointPose pose;
  pose.position = tree.to_mmvk * (glm::vec3(m.a4, m.b4, m.c4) * tree.metres_per_unit);
  const glm::vec3 column0(m.a1, m.b1, m.c1), column1(m.a2, m.b2, m.c2);
  const float length0 = glm::length(column0);
  if (!(length0 > 1e-20f)) return pose;  // a collapsed node keeps no orientation
  const glm::vec3 x = column0 / length0;
  glm::vec3 y = column1 - glm::dot(column1, x) * x;
  const float length1 = glm::length(y);
  if (!(length1 > 1e-20f)) return pose;
  y /= length1;
  const glm::mat3 frame(x, y, glm::cross(x, y));
  pose.rotation = glm::normalize(glm::quat_cast(tree.to_mmvk * frame));
  return pose;
}

bool finite(const JointPose& pose) {
  for (int i = 0; i < 3; ++i) {
    if (!std::isfinite(pose.position[i])) return false;
  }
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(pose.rotation[i])) return false;
  }
  return true;
}

}  // namespace

Result<NodeTree> build_node_tree(const aiScene& scene, const aiAnimation* animation, const glm::mat3& to_mmvk,
                                 float metres_per_unit, const std::string& where) {
  NodeTree tree;
  tree.to_mmvk = to_mmvk;
  tree.metres_per_unit = metres_per_unit;
  MMVK_TRY(flatten(scene.mRootNode, tree, where));
  const std::vector<bool> marked = joint_marks(scene, animation, tree);
  std::vector<int> joint_of(tree.nodes.size(), -1);
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    if (!marked[i]) continue;
    const int parent = tree.node_parent[i];
    joint_of[i] = static_cast<int>(tree.joints.size());
    tree.joints.push_back(static_cast<int>(i));
    const std::string name = tree.nodes[i]->mName.C_Str();
    tree.skeleton.names.push_back(name.empty() ? "node" + std::to_string(i) : name);
    tree.skeleton.parents.push_back(parent >= 0 ? joint_of[std::size_t(parent)] : -1);
  }
  if (tree.joints.empty()) {
    return make_error(where + ": no skeleton: no mesh has bones and the animation moves no node of the scene");
  }
  // The rest pose is the nodes' static transforms.
  std::vector<JointPose> rest(tree.joints.size());
  MMVK_TRY(joint_world_poses(tree, {}, 0.0, rest, where + ": rest pose"));
  Motion pose;
  pose.skeleton = tree.skeleton;
  pose.frame_count = 1;
  pose.local_positions.resize(tree.joints.size());
  pose.local_rotations.resize(tree.joints.size());
  store_local_pose(tree, rest, 0, pose);
  tree.skeleton.rest_offsets = std::move(pose.local_positions);
  return tree;
}

std::vector<const aiNodeAnim*> channels_by_node(const NodeTree& tree, const aiAnimation& animation) {
  const std::map<std::string_view, int> names = nodes_by_name(tree);
  std::vector<const aiNodeAnim*> channels(tree.nodes.size(), nullptr);
  for (unsigned c = 0; animation.mChannels != nullptr && c < animation.mNumChannels; ++c) {
    const aiNodeAnim* channel = animation.mChannels[c];
    if (channel == nullptr) continue;
    const auto it = names.find(std::string_view(channel->mNodeName.C_Str()));
    if (it != names.end() && channels[std::size_t(it->second)] == nullptr) channels[std::size_t(it->second)] = channel;
  }
  return channels;
}

Status joint_world_poses(const NodeTree& tree, const std::vector<const aiNodeAnim*>& channels, double ticks,
                         std::vector<JointPose>& world, const std::string& where) {
  std::vector<aiMatrix4x4> global(tree.nodes.size());
  for (std::size_t i = 0; i < tree.nodes.size(); ++i) {
    const aiNode& node = *tree.nodes[i];
    const aiNodeAnim* channel = channels.empty() ? nullptr : channels[i];
    const aiMatrix4x4 local = channel != nullptr ? sample_channel(node, *channel, ticks) : node.mTransformation;
    const int parent = tree.node_parent[i];
    global[i] = parent >= 0 ? global[std::size_t(parent)] * local : local;
  }
  for (std::size_t j = 0; j < tree.joints.size(); ++j) {
    world[j] = to_pose(global[std::size_t(tree.joints[j])], tree);
    if (!finite(world[j])) {
      return make_error(where + ": node '" + tree.skeleton.names[j] + "' has a transform that is not finite at " +
                        std::to_string(ticks) + " ticks");
    }
  }
  return {};
}

void store_local_pose(const NodeTree& tree, const std::vector<JointPose>& world, std::uint32_t frame, Motion& motion) {
  for (std::size_t j = 0; j < tree.joints.size(); ++j) {
    const int parent = tree.skeleton.parents[j];
    glm::vec3 position = world[j].position;
    glm::quat rotation = world[j].rotation;
    if (parent >= 0) {
      const glm::quat inverse = glm::inverse(world[std::size_t(parent)].rotation);
      position = inverse * (position - world[std::size_t(parent)].position);
      rotation = glm::normalize(inverse * rotation);
    }
    motion.local_positions[motion.index(frame, j)] = position;
    motion.local_rotations[motion.index(frame, j)] = rotation;
  }
}

}  // namespace mmvk::detail
