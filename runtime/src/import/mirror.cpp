// Left/right mirroring of a clip across the world YZ plane (x -> -x).
//
// Mirroring is defined on model-space poses: the mirrored joint j sits where
// its partner p(j) sat, reflected: P'_j = M P_p(j), with M = diag(-1, 1, 1).
// Its global rotation must carry j's rest offsets onto the reflected offsets
// of p(j)'s children, which gives R'_j = M R_p(j) K_j, where K_j is a
// reflection of j's local frame mapping each child offset onto its partner's
// offset. In local terms:
//   root:   L'_j = M L_p(j) K_j,          t'_j = M t_p(j)
//   others: L'_j = K_parent L_p(j) K_j,   t'_j = K_parent t_p(j)
// CMU rest frames are world aligned (K = reflect X everywhere); Bandai's are
// not (the hips reflect local Y, the chest local Z, the limbs local X), so K
// is chosen per joint from the rest offsets, among the three axis
// reflections, keeping the parent's where it fits nearly as well (so that a
// posture and its mirror have nearly the same local rotations). A reflection of axis a is -(180 degree turn about a), so
// K_a L K_b is the quaternion -(e_a q e_b) with e_a the unit pure quaternion
// of axis a; the minus sign makes mirror(mirror(m)) == m exactly (only
// component swaps and sign flips are involved, no rounding).
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "mmvk/import/character.hpp"
#include "mmvk/import/motion.hpp"

namespace mmvk {

namespace {

std::vector<std::string> partner_candidates(const std::string& name) {
  std::vector<std::string> out;
  // "LeftUpLeg" <-> "RightUpLeg", "leftEye" <-> "rightEye".
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 6> kWords{{
      {"Left", "Right"}, {"Right", "Left"}, {"left", "right"},
      {"right", "left"}, {"LEFT", "RIGHT"}, {"RIGHT", "LEFT"},
  }};
  for (const auto& [from, to] : kWords) {
    const std::size_t at = name.find(from);
    if (at != std::string::npos) out.push_back(name.substr(0, at) + std::string(to) + name.substr(at + from.size()));
  }
  const auto swap_side = [](char c) {
    switch (c) {
      case 'L': return 'R';
      case 'R': return 'L';
      case 'l': return 'r';
      case 'r': return 'l';
      default: return c;
    }
  };
  const std::size_t n = name.size();
  // "Foot_L", "foot.l", "Thigh-R", "Bip01 L Thigh".
  if (n >= 2 && (name[n - 2] == '_' || name[n - 2] == '.' || name[n - 2] == '-' || name[n - 2] == ' ')) {
    std::string swapped = name;
    swapped[n - 1] = swap_side(name[n - 1]);
    out.push_back(swapped);
  }
  for (const std::string_view infix : {" L ", " R ", "_L_", "_R_", "_l_", "_r_"}) {
    const std::size_t at = name.find(infix);
    if (at != std::string::npos) {
      std::string swapped = name;
      swapped[at + 1] = swap_side(name[at + 1]);
      out.push_back(swapped);
    }
  }
  // "L_Hip", "LHipJoint", "lThigh", "lfemur": a leading side letter. Safe
  // because a partner must exist ("lowerback" has no "rowerback").
  if (n >= 2) {
    std::string swapped = name;
    swapped[0] = swap_side(name[0]);
    out.push_back(swapped);
  }
  return out;
}

glm::quat axis_quat(int axis) {
  return axis == 0 ? glm::quat(0.0f, 1.0f, 0.0f, 0.0f)
                   : axis == 1 ? glm::quat(0.0f, 0.0f, 1.0f, 0.0f) : glm::quat(0.0f, 0.0f, 0.0f, 1.0f);
}

glm::vec3 reflect(int axis, glm::vec3 v) {
  v[axis] = -v[axis];
  return v;
}

constexpr int kWorldAxis = 0;  // mirror across the YZ plane: x -> -x

// How far (a fraction of the children's offsets) the parent's reflection
// axis may misplace a joint's children before the joint takes its own.
constexpr double kKeepParentAxisMisfit = 0.1;

// K_j per joint (0, 1, 2 = reflect local X, Y, Z); see the file comment.
std::vector<int> local_reflection_axes(const Skeleton& skeleton, const std::vector<int>& pairs) {
  const std::size_t n = skeleton.size();
  std::vector<std::vector<std::size_t>> children(n);
  for (std::size_t j = 0; j < n; ++j) {
    if (skeleton.parents[j] >= 0) children[static_cast<std::size_t>(skeleton.parents[j])].push_back(j);
  }
  std::vector<int> axes(n, kWorldAxis);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t partner = static_cast<std::size_t>(pairs[j]);
    const int parent = skeleton.parents[j];
    const int inherited = parent < 0 ? kWorldAxis : axes[static_cast<std::size_t>(parent)];
    if (partner < j) {
      axes[j] = axes[partner];  // decided together with the partner
      continue;
    }
    // Summing over both partners' children, in this fixed order, gives both
    // the same axis, which mirror(mirror(m)) == m relies on.
    std::array<double, 3> cost{0.0, 0.0, 0.0};
    double length = 0.0;  // of the children's offsets
    for (const std::size_t owner : {j, partner}) {
      for (const std::size_t c : children[owner]) {
        const glm::vec3 target = skeleton.rest_offsets[static_cast<std::size_t>(pairs[c])];
        for (int a = 0; a < 3; ++a) cost[a] += glm::length(reflect(a, skeleton.rest_offsets[c]) - target);
        length += glm::length(skeleton.rest_offsets[c]);
      }
      if (owner == partner) break;
    }
    int best = inherited;
    for (int a = 0; a < 3; ++a) {
      if (cost[a] < cost[best]) best = a;
    }
    // A joint whose axis differs from its parent's turns its mirrored local
    // rotation by a half turn (K_a L K_b with a != b), which the child then
    // turns back: the positions are right, but a blend between a clip and
    // its mirror swings through that half turn. So the parent's axis stays
    // unless it misfits by a real part of the bones (Bandai's frames, turned
    // by 90 degrees between joints), not by the few millimetres of an
    // asymmetric capture skeleton (CMU's spines: 3-5% of the bone). Leaves
    // and joints whose children are zero-length inherit it.
    if (cost[inherited] <= kKeepParentAxisMisfit * length) best = inherited;
    axes[j] = best;
  }
  return axes;
}

}  // namespace

std::vector<int> mirror_pairs(const Skeleton& skeleton) {
  const std::size_t n = skeleton.size();
  std::vector<int> pairs(n);
  for (std::size_t j = 0; j < n; ++j) {
    pairs[j] = static_cast<int>(j);
    for (const std::string& candidate : partner_candidates(skeleton.names[j])) {
      const int k = skeleton.find(candidate);
      if (k >= 0 && static_cast<std::size_t>(k) != j) {
        pairs[j] = k;
        break;
      }
    }
  }
  // Only mutual pairs count, so the mapping is an involution.
  for (std::size_t j = 0; j < n; ++j) {
    if (pairs[static_cast<std::size_t>(pairs[j])] != static_cast<int>(j)) pairs[j] = static_cast<int>(j);
  }
  return pairs;
}

Result<std::vector<int>> mirror_pairs(const Skeleton& skeleton, std::span<const BonePair> table) {
  std::vector<int> pairs = mirror_pairs(skeleton);
  if (table.empty()) return pairs;
  const std::size_t n = skeleton.size();
  std::vector<int> named(n, -1);  // the table's partner of each joint it names
  for (std::size_t i = 0; i < table.size(); ++i) {
    const std::string field = "mirror_bones[" + std::to_string(i) + "]";
    int ends[2] = {-1, -1};
    for (int k = 0; k < 2; ++k) {
      const std::string& bone = k == 0 ? table[i].first : table[i].second;
      Result<int> index = find_bone(skeleton, bone);
      if (!index.ok()) return make_error(field + "[" + std::to_string(k) + "]: " + index.message());
      ends[k] = *index;
    }
    for (int k = 0; k < 2; ++k) {
      const std::size_t j = static_cast<std::size_t>(ends[k]);
      if (named[j] >= 0 && !(ends[0] == ends[1] && k == 1)) {
        return make_error(field + "[" + std::to_string(k) + "]: joint " + skeleton.names[j] +
                          " is already in an earlier pair");
      }
      named[j] = ends[1 - k];
    }
  }
  // Heuristic partners of named joints lose their pair; named joints take
  // the table's. The result stays an involution.
  for (std::size_t j = 0; j < n; ++j) {
    if (named[j] < 0 && named[static_cast<std::size_t>(pairs[j])] >= 0) pairs[j] = static_cast<int>(j);
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (named[j] >= 0) pairs[j] = named[j];
  }
  return pairs;
}

Result<Motion> mirror(const Motion& motion) { return mirror(motion, {}); }

Result<Motion> mirror(const Motion& motion, std::span<const BonePair> table) {
  const Skeleton& skeleton = motion.skeleton;
  const std::size_t n = skeleton.size();
  if (skeleton.parents.size() != n || skeleton.rest_offsets.size() != n) {
    return make_error("mirror: skeleton names, parents and rest offsets differ in size");
  }
  if (motion.local_positions.size() != motion.frame_count * n || motion.local_rotations.size() != motion.frame_count * n) {
    return make_error("mirror: local transforms are not sized frame_count x joints");
  }
  MMVK_ASSIGN_OR_RETURN(const std::vector<int> pairs, mirror_pairs(skeleton, table));
  for (std::size_t j = 0; j < n; ++j) {
    const int parent = skeleton.parents[j];
    if (parent >= static_cast<int>(j)) return make_error("mirror: joint " + skeleton.names[j] + " follows its child");
    const int partner_parent = skeleton.parents[static_cast<std::size_t>(pairs[j])];
    const int expected = parent < 0 ? -1 : pairs[static_cast<std::size_t>(parent)];
    if (partner_parent != expected) {
      return make_error("mirror: joints " + skeleton.names[j] + " and " + skeleton.names[static_cast<std::size_t>(pairs[j])] +
                        " are left/right partners but their parents are not");
    }
  }
  const std::vector<int> axes = local_reflection_axes(skeleton, pairs);

  Motion out = motion;
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t source = motion.index(f, static_cast<std::size_t>(pairs[j]));
      const int parent = skeleton.parents[j];
      const int parent_axis = parent < 0 ? kWorldAxis : axes[static_cast<std::size_t>(parent)];
      out.local_positions[out.index(f, j)] = reflect(parent_axis, motion.local_positions[source]);
      out.local_rotations[out.index(f, j)] =
          -(axis_quat(parent_axis) * motion.local_rotations[source] * axis_quat(axes[j]));
    }
  }
  return out;
}

}  // namespace mmvk
