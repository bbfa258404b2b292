#include "database/animation_build.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "features/foot_contacts.hpp"
#include "mmvk/import/character.hpp"

namespace mmvk::detail {

namespace {

// Joint translations within this distance (metres, per component) of a
// clip's first frame count as constant, and constants within it of the
// first clip's as shared. Rounding of resampling stays far below it; the FK
// error it can add over a chain of ten joints stays below the 1e-4 m the
// tests hold the stored poses to.
constexpr float kConstantTolerance = 5e-6f;

bool near(const glm::vec3& a, const glm::vec3& b) {
  return std::abs(a.x - b.x) <= kConstantTolerance && std::abs(a.y - b.y) <= kConstantTolerance &&
         std::abs(a.z - b.z) <= kConstantTolerance;
}

// The joints the pose collapses: strict ancestors of the hips (static
// scene roots such as Bandai's joint_Root). 1 marks one.
std::vector<std::uint8_t> collapsed_joints(const Skeleton& skeleton, const std::string& hips_bone) {
  std::vector<std::uint8_t> collapsed(skeleton.size(), 0);
  if (Result<int> hips = find_bone(skeleton, hips_bone); hips.ok()) {
    for (int p = skeleton.parents[static_cast<std::size_t>(*hips)]; p >= 0; p = skeleton.parents[static_cast<std::size_t>(p)]) {
      collapsed[static_cast<std::size_t>(p)] = 1;
    }
  }
  return collapsed;
}

// The pose is stored relative to the character root. Collapsed joints become
// the identity at the character root, and every joint hanging directly off
// them (or off nothing) stores its model-space transform re-expressed in
// character space. So the hips carry a short translation (about 1 m up) and
// no far-away scene origin acts as a lever arm when poses are blended.
// Fills out's rotations and root, and `translations` [frames x joints].
void to_character_space(const Motion& motion, const CharacterRoot& root, const std::string& hips_bone,
                        std::span<const glm::vec3> positions, std::span<const glm::quat> globals, ClipAnimation& out,
                        std::vector<glm::vec3>& translations) {
  const std::size_t joints = motion.joint_count();
  const std::vector<std::uint8_t> collapsed = collapsed_joints(motion.skeleton, hips_bone);
  translations.resize(std::size_t{motion.frame_count} * joints);
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  for (std::uint32_t f = 0; f < motion.frame_count; ++f) {
    const glm::vec3 facing = root.facings[f];
    const float yaw = std::atan2(facing.x, facing.z);
    const glm::quat to_character = glm::angleAxis(-yaw, up);
    out.root_positions[f] = glm::vec3(root.positions[f].x, 0.0f, root.positions[f].z);
    out.root_yaws[f] = yaw;
    for (std::size_t j = 0; j < joints; ++j) {
      const std::size_t i = motion.index(f, j);
      const int parent = motion.skeleton.parents[j];
      glm::quat q = motion.local_rotations[i];
      glm::vec3 t = motion.local_positions[i];
      if (collapsed[j]) {
        q = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
        t = glm::vec3(0.0f);
      } else if (parent < 0 || collapsed[static_cast<std::size_t>(parent)]) {
        q = to_character * globals[i];
        t = to_character * (positions[i] - out.root_positions[f]);
      }
      out.rotations[i] = glm::normalize(q);
      translations[i] = t;
    }
  }
}

// Translations stored once per joint where they stay constant over the clip,
// per frame for the varying joints only.
void split_translations(const Motion& motion, std::span<const glm::vec3> translations, ClipAnimation& out) {
  const std::size_t joints = motion.joint_count();
  const std::uint32_t frames = motion.frame_count;
  out.constant.resize(joints);
  for (std::size_t j = 0; j < joints; ++j) {
    out.constant[j] = frames > 0 ? translations[j] : motion.skeleton.rest_offsets[j];
    for (std::uint32_t f = 1; f < frames; ++f) {
      if (!near(translations[f * joints + j], out.constant[j])) {
        out.varying.push_back(static_cast<std::uint32_t>(j));
        break;
      }
    }
  }
  out.translations.resize(std::size_t{frames} * out.varying.size());
  for (std::uint32_t f = 0; f < frames; ++f) {
    for (std::size_t v = 0; v < out.varying.size(); ++v) {
      out.translations[f * out.varying.size() + v] = translations[f * joints + out.varying[v]];
    }
  }
}

}  // namespace

Result<ClipAnimation> extract_clip_animation(const Motion& motion, const CharacterRoot& root,
                                             const std::string& hips_bone, const FootContactParams& params,
                                             std::string source) {
  const std::size_t joints = motion.joint_count();
  const std::uint32_t frames = motion.frame_count;
  if (root.positions.size() != frames || root.facings.size() != frames) {
    return make_error(source + ": character root is not sized to the clip");
  }
  ClipAnimation out;
  out.skeleton = motion.skeleton;
  out.source = std::move(source);
  out.frame_count = frames;
  out.rotations.resize(std::size_t{frames} * joints);
  out.root_positions.resize(frames);
  out.root_yaws.resize(frames);
  out.contacts.assign(frames, 0);

  // Model-space transforms, for the character-space re-expression and the
  // contacts.
  std::vector<glm::vec3> positions(std::size_t{frames} * joints);
  std::vector<glm::quat> globals(std::size_t{frames} * joints);
  forward_kinematics_clip(motion, positions, globals);
  std::vector<glm::vec3> translations;
  to_character_space(motion, root, hips_bone, positions, globals, out, translations);
  split_translations(motion, translations, out);

  ClipContacts contacts = detect_foot_contacts(motion.skeleton, positions, frames, motion.fps, params);
  // A side without a toe keeps its heel as its contact joint, so readers of
  // contact_joints (sliding meters, the viewer) always have a point.
  for (std::size_t s = 0; s < 2; ++s) {
    out.contact_joints[s] = contacts.toes[s] >= 0 ? contacts.toes[s] : contacts.heels[s];
  }
  out.heel_joints = contacts.heels;
  out.contacts = std::move(contacts.bits);
  return out;
}

namespace {

// How `clip`'s hierarchy differs from `first`'s, in a few words.
std::string skeleton_difference(const Skeleton& clip, const Skeleton& first) {
  if (clip.size() != first.size()) {
    return std::to_string(clip.size()) + " joints against " + std::to_string(first.size());
  }
  for (std::size_t j = 0; j < clip.size(); ++j) {
    if (clip.names[j] != first.names[j]) return "joint " + std::to_string(j) + " is '" + clip.names[j] + "', not '" + first.names[j] + "'";
    if (clip.parents[j] != first.parents[j]) return "joint '" + clip.names[j] + "' has another parent";
  }
  return "the same joints";
}

// The section holds one skeleton: the error names every clip whose
// hierarchy differs from the first clip's (a few, then a count), how, and
// what to do about it.
Status check_one_skeleton(std::span<const ClipAnimation> clips) {
  const ClipAnimation& first = clips[0];
  constexpr std::size_t kNamed = 4;
  std::string named;
  std::size_t differing = 0;
  for (const ClipAnimation& clip : clips) {
    if (clip.skeleton.names == first.skeleton.names && clip.skeleton.parents == first.skeleton.parents) continue;
    if (differing++ < kNamed) {
      named += (named.empty() ? "" : "; ") + clip.source + " (" + skeleton_difference(clip.skeleton, first.skeleton) + ")";
    }
  }
  if (differing == 0) return {};
  if (differing > kNamed) named += "; and " + std::to_string(differing - kNamed) + " more";
  return make_error("the animation section holds one skeleton, and " + std::to_string(differing) +
                    " clip" + (differing == 1 ? "'s hierarchy differs" : "s' hierarchies differ") + " from " +
                    first.source + "'s (" + std::to_string(first.skeleton.size()) + " joints): " + named +
                    ". Build each skeleton's clips into a database of its own (or retarget them to one "
                    "skeleton) to animate them; --no-animation builds the features alone without this warning");
}

}  // namespace

Result<AnimationData> assemble_animation(std::span<const ClipAnimation> clips, const FootContactParams& contacts,
                                         RotationEncoding encoding, std::span<const BonePair> mirror_bones) {
  if (clips.empty()) return make_error("animation: no clips");
  const ClipAnimation& first = clips[0];
  const std::size_t joints = first.skeleton.size();
  std::uint64_t frames = 0;
  MMVK_TRY(check_one_skeleton(clips));
  for (const ClipAnimation& clip : clips) frames += clip.frame_count;
  AnimationData out;
  out.skeleton = first.skeleton;
  Result<std::vector<int>> pairs = mirror_pairs(out.skeleton, mirror_bones);
  if (!pairs.ok()) return make_error("animation: " + pairs.message());
  out.mirror_pairs = std::move(*pairs);
  out.contact_params = contacts;
  out.encoding = encoding;
  out.contact_joints = first.contact_joints;
  out.heel_joints = first.heel_joints;
  out.frame_count = static_cast<std::uint32_t>(frames);

  // A joint needs per-frame translations when it varies in some clip or
  // its constant differs between clips; otherwise the shared constant is
  // its rest offset (the effective translation, which for BVH joints with
  // position channels may differ from the file's OFFSET).
  std::vector<std::uint8_t> translated(joints, 0);
  for (const ClipAnimation& clip : clips) {
    for (std::uint32_t j : clip.varying) translated[j] = 1;
    for (std::size_t j = 0; j < joints; ++j) {
      if (!near(clip.constant[j], first.constant[j])) translated[j] = 1;
    }
  }
  for (std::size_t j = 0; j < joints; ++j) {
    if (translated[j]) {
      out.translated_joints.push_back(static_cast<std::uint32_t>(j));
    } else {
      out.skeleton.rest_offsets[j] = first.constant[j];
    }
  }
  const std::size_t count = out.translated_joints.size();
  out.local_rotations.reserve(frames * joints);
  out.local_translations.resize(frames * count);
  out.root_positions.reserve(frames);
  out.root_yaws.reserve(frames);
  out.contacts.reserve(frames);
  std::size_t base = 0;
  for (const ClipAnimation& clip : clips) {
    out.local_rotations.insert(out.local_rotations.end(), clip.rotations.begin(), clip.rotations.end());
    out.root_positions.insert(out.root_positions.end(), clip.root_positions.begin(), clip.root_positions.end());
    out.root_yaws.insert(out.root_yaws.end(), clip.root_yaws.begin(), clip.root_yaws.end());
    out.contacts.insert(out.contacts.end(), clip.contacts.begin(), clip.contacts.end());
    for (std::size_t t = 0; t < count; ++t) {
      const std::uint32_t j = out.translated_joints[t];
      const auto it = std::find(clip.varying.begin(), clip.varying.end(), j);
      const std::size_t v = static_cast<std::size_t>(it - clip.varying.begin());
      for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
        out.local_translations[(base + f) * count + t] =
            it == clip.varying.end() ? clip.constant[j] : clip.translations[f * clip.varying.size() + v];
      }
    }
    base += clip.frame_count;
  }
  return out;
}

}  // namespace mmvk::detail
