// Bone roles ("@left_foot") -> joint indices, by the naming conventions of
// the skeletons in ../shared/data/SOURCES.md plus common DCC exports.
#include <algorithm>
#include <array>
#include <cctype>
#include <string>
#include <vector>

#include "common/name_table.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/common/input_text.hpp"

namespace mmvk {

namespace {

// Lower case, letters and digits only: "Foot_L" -> "footl", "LeftUpLeg" ->
// "leftupleg", so one table entry covers "Foot_L", "Foot.L" and "foot_l".
std::string normalize(std::string_view name) {
  std::string out;
  out.reserve(name.size());
  for (const char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (std::isalnum(u)) out += static_cast<char>(std::tolower(u));
  }
  return out;
}

struct RoleNames {
  std::string_view role;
  std::string_view description;
  // Normalized joint names, most specific first. Sources: CMU ASF (lfemur),
  // cgspeed max (LeftHip), cgspeed mb and LAFAN1/Mixamo (LeftUpLeg), Bandai
  // (UpperLeg_L), DAZ (lThigh), and a few common exports.
  std::array<std::string_view, 10> names;
};

constexpr std::array<RoleNames, 14> kRoles{{
    {"left_upper_leg", "left upper leg (hip joint)",
     {"lfemur", "leftupleg", "upperlegl", "lthigh", "lefthip", "leftthigh", "leftupperleg", "thighl", "lupleg", "lhip"}},
    {"right_upper_leg", "right upper leg (hip joint)",
     {"rfemur", "rightupleg", "upperlegr", "rthigh", "righthip", "rightthigh", "rightupperleg", "thighr", "rupleg",
      "rhip"}},
    {"left_lower_leg", "left lower leg (knee)",
     {"ltibia", "leftleg", "lowerlegl", "lshin", "leftknee", "leftshin", "leftlowerleg", "shinl", "leftcalf", "lknee"}},
    {"right_lower_leg", "right lower leg (knee)",
     {"rtibia", "rightleg", "lowerlegr", "rshin", "rightknee", "rightshin", "rightlowerleg", "shinr", "rightcalf",
      "rknee"}},
    {"left_foot", "left foot (ankle)",
     {"lfoot", "leftfoot", "footl", "leftankle", "anklel", "lankle", "leftfootankle", "", "", ""}},
    {"right_foot", "right foot (ankle)",
     {"rfoot", "rightfoot", "footr", "rightankle", "ankler", "rankle", "rightfootankle", "", "", ""}},
    {"left_toe", "left toe (ball of the foot)",
     {"ltoes", "lefttoebase", "toesl", "lefttoe", "toel", "lefttoes", "ltoe", "ltoebase", "", ""}},
    {"right_toe", "right toe (ball of the foot)",
     {"rtoes", "righttoebase", "toesr", "righttoe", "toer", "righttoes", "rtoe", "rtoebase", "", ""}},
    {"head", "head", {"head", "", "", "", "", "", "", "", "", ""}},
    {"left_hand", "left hand (wrist)",
     {"lwrist", "leftwrist", "wristl", "lefthand", "handl", "lhand", "", "", "", ""}},
    {"right_hand", "right hand (wrist)",
     {"rwrist", "rightwrist", "wristr", "righthand", "handr", "rhand", "", "", "", ""}},
    // The shoulder joint (upper arm), not the clavicle: "LeftShoulder" is the
    // clavicle in cgspeed mb and Mixamo (whose upper arm is "LeftArm", found
    // first) but the upper arm in cgspeed max, so it comes last.
    {"left_shoulder", "left shoulder (upper arm)",
     {"lhumerus", "leftarm", "upperarml", "lshldr", "leftupperarm", "larm", "lupperarm", "upperarmleft", "leftshoulder",
      ""}},
    {"right_shoulder", "right shoulder (upper arm)",
     {"rhumerus", "rightarm", "upperarmr", "rshldr", "rightupperarm", "rarm", "rupperarm", "upperarmright",
      "rightshoulder", ""}},
    {"hips", "hips (pelvis)", {"hips", "hip", "pelvis", "root", "", "", "", "", "", ""}},
}};

// The joints' names as messages show them: names come from the BVH file, so
// each is escaped and cut (printable_text), and a skeleton of thousands of
// joints lists its first kListedJoints.
std::string list_joints(const Skeleton& skeleton) {
  constexpr std::size_t kListedJoints = 100;
  std::string out;
  for (std::size_t i = 0; i < skeleton.names.size() && i < kListedJoints; ++i) {
    if (i) out += ", ";
    out += printable_text(skeleton.names[i]);
  }
  if (skeleton.names.size() > kListedJoints) {
    out += " and " + std::to_string(skeleton.names.size() - kListedJoints) + " more";
  }
  return out;
}

int find_by_names(const Skeleton& skeleton, const RoleNames& role) {
  std::vector<std::string> normalized;
  normalized.reserve(skeleton.size());
  for (const std::string& name : skeleton.names) normalized.push_back(normalize(name));
  for (const std::string_view candidate : role.names) {
    if (candidate.empty()) continue;
    for (std::size_t j = 0; j < normalized.size(); ++j) {
      if (normalized[j] == candidate) return static_cast<int>(j);
    }
  }
  // Then a namespaced or prefixed name ("mixamorig:LeftFoot", "Bip01 L
  // Thigh" -> "bip01lthigh"): a unique joint whose name ends with a
  // candidate of at least 5 characters.
  for (const std::string_view candidate : role.names) {
    if (candidate.size() < 5) continue;
    int found = -1;
    int matches = 0;
    for (std::size_t j = 0; j < normalized.size(); ++j) {
      const std::string& name = normalized[j];
      if (name.size() > candidate.size() && name.compare(name.size() - candidate.size(), candidate.size(), candidate) == 0) {
        found = static_cast<int>(j);
        ++matches;
      }
    }
    if (matches == 1) return found;
  }
  return -1;
}

const RoleNames* role_named(std::string_view role) {
  return detail::find_named(std::span<const RoleNames>(kRoles), &RoleNames::role, role);
}

std::string known_roles() {
  return detail::name_list(std::span<const RoleNames>(kRoles), &RoleNames::role, '@', false);
}

// Deepest joint that is an ancestor of (or equal to) both a and b.
int common_ancestor(const Skeleton& skeleton, int a, int b) {
  while (a != b) {
    // Parents have smaller indices, so stepping up the larger index converges.
    if (a > b) {
      a = skeleton.parents[static_cast<std::size_t>(a)];
    } else {
      b = skeleton.parents[static_cast<std::size_t>(b)];
    }
    if (a < 0 || b < 0) return -1;
  }
  return a;
}

}  // namespace

Result<int> find_bone(const Skeleton& skeleton, std::string_view bone) {
  if (bone.empty()) return make_error("bone name is empty");
  if (bone.front() != '@') {
    const int index = skeleton.find(bone);
    if (index < 0) {
      return make_error("bone '" + printable_text(bone) + "' not found; the skeleton's joints are: " +
                        list_joints(skeleton));
    }
    return index;
  }
  const std::string_view role_name = bone.substr(1);
  const RoleNames* role = role_named(role_name);
  if (!role) return make_error("unknown bone role '" + printable_text(bone) + "'; known roles: " + known_roles());
  if (role_name == "hips") {
    // The pelvis is where the two legs meet: the deepest common ancestor of
    // the upper legs. This skips static scene roots above it (Bandai's
    // joint_Root) whatever they are called.
    const int left = find_by_names(skeleton, *role_named("left_upper_leg"));
    const int right = find_by_names(skeleton, *role_named("right_upper_leg"));
    if (left >= 0 && right >= 0 && left != right) {
      const int hips = common_ancestor(skeleton, left, right);
      if (hips >= 0) return hips;
    }
  }
  const int index = find_by_names(skeleton, *role);
  if (index < 0) {
    std::string names;
    for (const std::string_view candidate : role->names) {
      if (candidate.empty()) continue;
      if (!names.empty()) names += ", ";
      names += candidate;
    }
    return make_error("bone '" + printable_text(bone) + "' not found: no joint is named like a " +
                      std::string(role->description) + " (" + names +
                      ", compared lower-case without punctuation); the skeleton's joints are: " +
                      list_joints(skeleton));
  }
  return index;
}

}  // namespace mmvk
