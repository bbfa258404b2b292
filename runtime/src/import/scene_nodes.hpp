// The node tree of an assimp scene as mmvk's skeleton, and the sampling of
// its joints' world transforms (scene_import.cpp's inner half).
#pragma once

#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "mmvk/import/motion.hpp"
#include "mmvk/common/status.hpp"

struct aiScene;
struct aiNode;
struct aiAnimation;
struct aiNodeAnim;

namespace mmvk::detail {

// The most nodes a scene may have: a hostile file's tree is refused before
// its per-frame walk would take forever.
inline constexpr std::size_t kMaxSceneNodes = std::size_t{1} << 20;

// A joint's world transform in mmvk's frame: metres, Y-up.
struct JointPose {
  glm::vec3 position{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
};

struct NodeTree {
  std::vector<const aiNode*> nodes;  // every node, depth-first from the root node
  std::vector<int> node_parent;      // [nodes], -1 for the root node
  std::vector<int> joints;           // node index of each joint, depth-first
  Skeleton skeleton;                 // the joints: names, parents, rest offsets (metres)
  glm::mat3 to_mmvk{1.0f};           // file axes -> mmvk's (a rotation)
  float metres_per_unit = 1.0f;
};

// The skeleton of `scene` for `animation` (scene_import.hpp: the skin's
// joints, else the animated nodes, with their ancestors below the root
// node; the root node too when they have several tops). `where` names the
// file and animation in errors.
Result<NodeTree> build_node_tree(const aiScene& scene, const aiAnimation* animation, const glm::mat3& to_mmvk,
                                 float metres_per_unit, const std::string& where);

// The animation's channel of each node ([tree.nodes], null where none).
std::vector<const aiNodeAnim*> channels_by_node(const NodeTree& tree, const aiAnimation& animation);

// Every joint's world pose at `ticks` (the animation's time unit); nodes
// without a channel keep their static transform. An empty `channels` gives
// the rest pose. Errors (`where`) on a non-finite key or transform.
Status joint_world_poses(const NodeTree& tree, const std::vector<const aiNodeAnim*>& channels, double ticks,
                         std::vector<JointPose>& world, const std::string& where);

// World poses -> frame `frame` of `motion`'s local transforms.
void store_local_pose(const NodeTree& tree, const std::vector<JointPose>& world, std::uint32_t frame, Motion& motion);

}  // namespace mmvk::detail
