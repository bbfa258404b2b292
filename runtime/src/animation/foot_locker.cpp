// Foot locking (foot_locker.hpp): per foot a horizontal and a yaw correction
// that hold a planted contact point on its anchor and decay after release;
// the hips lowered for out-of-reach targets; two-bone IK on the result.
#include "mmvk/animation/foot_locker.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <string>

#include <glm/geometric.hpp>

#include "mmvk/import/character.hpp"
#include "mmvk/animation/foot_ik.hpp"
#include "mmvk/animation/spring.hpp"
#include "yaw.hpp"

namespace mmvk {

namespace {

const glm::vec3 kUp(0.0f, 1.0f, 0.0f);
const glm::quat kIdentity(1.0f, 0.0f, 0.0f, 0.0f);

// A released correction smaller and slower than this (metres or radians, and
// per second) is set to zero: the leg is then left exactly as animated, and
// is not solved at all.
constexpr float kSettled = 1e-5f;
// A step's length in time and its height (step()): about a quick shuffle's.
constexpr float kStepSeconds = 0.25f;
constexpr float kStepHeightRatio = 0.25f;  // of the distance it covers
constexpr float kMaxStepHeight = 0.06f;    // metres
constexpr float kSettledRate = 1e-4f;
// A unit foot heading shorter than this horizontally (within 14 degrees of
// vertical) has no reliable yaw: the yaw correction is held meanwhile, and
// the lock's heading taken afresh when the foot levels again.
constexpr float kVerticalHeading = 0.25f;

// Marks a lock whose foot heading is (or was last) vertical: its anchor yaw
// is set on the next tick with a heading, so the yaw correction carries on.
constexpr float kNoYaw = std::numeric_limits<float>::quiet_NaN();

constexpr std::uint8_t kPlantedBit[2] = {kContactLeft, kContactRight};
constexpr std::uint8_t kHeelBit[2] = {kContactLeftHeel, kContactRightHeel};
constexpr std::uint8_t kToeBit[2] = {kContactLeftToe, kContactRightToe};
// Contact points: the heel (the ankle joint) or the toe joint.
constexpr std::uint8_t kHeel = 0;
constexpr std::uint8_t kToe = 1;

// The knee's bend direction: an animated leg bent less than kBentFrom of
// its length (the knee's offset from the hip-ankle line; 2%: a knee flexed
// about 5 degrees) says nothing about where its knee points, as motion
// capture's noise turns that offset about the leg, even behind it; one bent
// kBentAt (10%, about 23 degrees) says it exactly. In between the kept
// direction turns toward the animated one, the faster the more it is bent:
// by the fraction w = smoothstep of the bend in kKneeFollowTime.
constexpr float kBentFrom = 0.02f;
constexpr float kBentAt = 0.1f;
constexpr float kKneeFollowTime = 1.0f / 30.0f;

using detail::yaw_rotation;

glm::vec3 horizontal(const glm::vec3& v) { return {v.x, 0.0f, v.z}; }

// True when `ancestor` is a strict ancestor of `joint`.
bool descends(const std::vector<int>& parents, int ancestor, int joint) {
  for (int j = parents[static_cast<std::size_t>(joint)]; j >= 0; j = parents[static_cast<std::size_t>(j)]) {
    if (j == ancestor) return true;
  }
  return false;
}

// The yaw of a world direction (radians, 0 along +Z), false when it is
// (nearly) vertical.
bool heading_yaw(const glm::vec3& direction, float& yaw) {
  if (direction.x * direction.x + direction.z * direction.z < kVerticalHeading * kVerticalHeading) return false;
  yaw = std::atan2(direction.x, direction.z);
  return true;
}

// The foot's forward direction in its own frame: toward its toe where the toe
// is its child, else the direction that faces the character's forward (+Z)
// on the first frame, else +Z.
glm::vec3 foot_heading(const AnimationData& animation, const FootLocker::Leg& leg) {
  const Skeleton& skeleton = animation.skeleton;
  if (leg.toe >= 0 && skeleton.parents[static_cast<std::size_t>(leg.toe)] == leg.foot) {
    const glm::vec3 offset = skeleton.rest_offsets[static_cast<std::size_t>(leg.toe)];
    if (glm::length(offset) > 1e-4f) return glm::normalize(offset);
  }
  if (animation.frame_count == 0 || animation.local_rotations.size() < animation.joint_count()) {
    return glm::vec3(0.0f, 0.0f, 1.0f);
  }
  glm::quat global = kIdentity;
  for (int j = leg.foot; j >= 0; j = skeleton.parents[static_cast<std::size_t>(j)]) {
    global = animation.local_rotations[static_cast<std::size_t>(j)] * global;
  }
  return glm::normalize(glm::inverse(global) * glm::vec3(0.0f, 0.0f, 1.0f));
}

// The direction a leg's knee bends toward (world, unit) this tick, from the
// kept one (character space; zero: none yet, the character's forward) and
// the animated leg; the kept one is updated. Continuous in time for any
// animation: a nearly straight leg keeps the direction its knee had. A leg
// shown as animated (`solved` false) takes its animated knee's direction as
// soon as it is bent at all (past kBentFrom): that is where its knee is
// shown, so a solve that starts next tick starts from it.
glm::vec3 follow_knee(glm::vec3& kept, const glm::vec3& hip, const glm::vec3& knee, const glm::vec3& ankle,
                      const glm::quat& root, float dt, bool solved) {
  const glm::vec3 previous = kept == glm::vec3(0.0f) ? root * glm::vec3(0.0f, 0.0f, 1.0f) : root * kept;
  const glm::vec3 hip_ankle = ankle - hip;
  const float extension = glm::length(hip_ankle);
  const float leg = glm::length(knee - hip) + glm::length(ankle - knee);
  if (!(extension > 1e-6f)) return previous;
  const glm::vec3 axis = hip_ankle / extension;
  const glm::vec3 animated = (knee - hip) - axis * glm::dot(knee - hip, axis);
  const float animated_length = glm::length(animated);
  const float x = std::clamp((animated_length / leg - kBentFrom) / (kBentAt - kBentFrom), 0.0f, 1.0f);
  const float w = x * x * (3.0f - 2.0f * x);
  glm::vec3 direction = previous;
  if (w >= 1.0f || (!solved && w > 0.0f)) {
    direction = animated / animated_length;
  } else if (w > 0.0f && dt > 0.0f) {
    // Turned about the axis between them (through the side when they are
    // opposite), never through zero as a blend of the two would.
    const float fraction = 1.0f - std::pow(1.0f - w, dt / kKneeFollowTime);
    direction = glm::slerp(kIdentity, rotation_between(previous, animated), fraction) * previous;
  }
  direction -= axis * glm::dot(direction, axis);
  const float length = glm::length(direction);
  if (!(length > 1e-6f)) return previous;  // along the leg: the animated leg turned onto it; keep the last
  direction /= length;
  kept = glm::conjugate(root) * direction;
  return direction;
}

}  // namespace

Status FootIkParams::validate() const {
  auto fail = [](const char* field, const char* rule, float value) {
    return Status(make_error(std::string("foot IK: ") + field + " must be " + rule + ", got " + std::to_string(value)));
  };
  if (!(std::isfinite(soft_reach_start) && soft_reach_start > 0.0f && soft_reach_start <= 1.0f)) {
    return fail("soft_reach_start", "in (0, 1]", soft_reach_start);
  }
  const struct {
    const char* name;
    float value;
  } positive[] = {{"unlock_distance", unlock_distance},
                  {"max_yaw_correction", max_yaw_correction},
                  {"release_half_life", release_half_life},
                  {"hip_half_life", hip_half_life}};
  for (const auto& check : positive) {
    if (!(std::isfinite(check.value) && check.value > 0.0f)) return fail(check.name, "finite and > 0", check.value);
  }
  if (!(std::isfinite(max_hip_drop) && max_hip_drop >= 0.0f)) return fail("max_hip_drop", "finite and >= 0", max_hip_drop);
  if (!(std::isfinite(max_hip_goal_rate) && max_hip_goal_rate >= 0.0f)) {
    return fail("max_hip_goal_rate", "finite and >= 0", max_hip_goal_rate);
  }
  if (!std::isfinite(floor_height)) return fail("floor_height", "finite", floor_height);
  return {};
}

Result<FootLocker> FootLocker::create(const AnimationData& animation, std::uint32_t characters,
                                      const FootIkParams& params) {
  if (characters == 0) return make_error("foot IK: characters must be at least 1");
  MMVK_TRY(params.validate());
  const Skeleton& skeleton = animation.skeleton;
  auto resolve = [&](const char* role, int& joint) -> Status {
    Result<int> found = find_bone(skeleton, role);
    if (!found.ok()) return make_error(std::string("foot IK: ") + found.message());
    joint = *found;
    return {};
  };
  // Joint `below` must hang under joint `above` (the roles name them).
  auto under = [&](const char* above_role, int above, const char* below_role, int below) -> Status {
    if (descends(skeleton.parents, above, below)) return {};
    return make_error(std::string("foot IK: ") + below_role + " (" + skeleton.names[static_cast<std::size_t>(below)] +
                      ") is not below " + above_role + " (" + skeleton.names[static_cast<std::size_t>(above)] +
                      ") in the skeleton");
  };
  static constexpr const char* kRoles[2][4] = {{"@left_upper_leg", "@left_lower_leg", "@left_foot", "@left_toe"},
                                               {"@right_upper_leg", "@right_lower_leg", "@right_foot", "@right_toe"}};
  FootLocker locker;
  MMVK_TRY(resolve("@hips", locker.hips_));
  for (std::size_t side = 0; side < 2; ++side) {
    Leg& leg = locker.legs_[side];
    const char* const* roles = kRoles[side];
    MMVK_TRY(resolve(roles[0], leg.upper));
    MMVK_TRY(resolve(roles[1], leg.lower));
    MMVK_TRY(resolve(roles[2], leg.foot));
    // The toe is optional (DAZ skeletons have none): the ankle is then the
    // only contact point.
    Result<int> toe = find_bone(skeleton, roles[3]);
    leg.toe = toe.ok() ? *toe : -1;
    MMVK_TRY(under("@hips", locker.hips_, roles[0], leg.upper));
    MMVK_TRY(under(roles[0], leg.upper, roles[1], leg.lower));
    MMVK_TRY(under(roles[1], leg.lower, roles[2], leg.foot));
    if (leg.toe >= 0) MMVK_TRY(under(roles[2], leg.foot, roles[3], leg.toe));
    locker.heading_[side] = foot_heading(animation, leg);
  }
  if (locker.legs_[0].upper == locker.legs_[1].upper || descends(skeleton.parents, locker.legs_[0].upper, locker.legs_[1].upper) ||
      descends(skeleton.parents, locker.legs_[1].upper, locker.legs_[0].upper)) {
    return make_error("foot IK: @left_upper_leg and @right_upper_leg must be separate branches of the skeleton");
  }

  const std::size_t joints = skeleton.size();
  locker.characters_ = characters;
  locker.params_ = params;
  locker.parents_ = skeleton.parents;
  locker.below_hips_.assign(joints, 0);
  for (std::size_t j = 0; j < joints; ++j) {
    const int joint = static_cast<int>(j);
    locker.below_hips_[j] = joint == locker.hips_ || descends(skeleton.parents, locker.hips_, joint);
    bool rotated = joint == locker.hips_ || descends(skeleton.parents, joint, locker.hips_);
    for (std::size_t side = 0; side < 2; ++side) {
      const int upper = locker.legs_[side].upper;
      if (joint == upper || descends(skeleton.parents, upper, joint)) locker.leg_joints_[side].push_back(joint);
      rotated = rotated || joint == upper || descends(skeleton.parents, joint, upper) ||
                descends(skeleton.parents, upper, joint);
    }
    if (rotated) locker.rotated_joints_.push_back(joint);
  }
  if (joints > kStackJoints) locker.wide_scratch_.resize(std::size_t{characters} * joints);
  const std::size_t feet = std::size_t{characters} * 2;
  locker.locked_.assign(feet, 0);
  locker.clamped_.assign(feet, 0);
  locker.point_.assign(feet, kHeel);
  locker.drifted_.assign(feet, 0);
  locker.anchor_.assign(feet, glm::vec3(0.0f));
  locker.offset_.assign(feet, glm::vec3(0.0f));
  locker.offset_rate_.assign(feet, glm::vec3(0.0f));
  locker.knee_direction_.assign(feet, glm::vec3(0.0f));
  locker.anchor_yaw_.assign(feet, 0.0f);
  locker.yaw_offset_.assign(feet, 0.0f);
  locker.yaw_rate_.assign(feet, 0.0f);
  locker.steps_.assign(feet, Step{});
  locker.hip_drop_.assign(characters, 0.0f);
  locker.hip_drop_rate_.assign(characters, 0.0f);
  locker.hip_goal_.assign(characters, 0.0f);
  return locker;
}

Status FootLocker::set_params(const FootIkParams& params) {
  MMVK_TRY(params.validate());
  params_ = params;
  return {};
}

void FootLocker::clear(std::uint32_t b) {
  for (std::size_t f = std::size_t{b} * 2; f < std::size_t{b} * 2 + 2; ++f) {
    locked_[f] = clamped_[f] = drifted_[f] = 0;
    point_[f] = kHeel;
    anchor_[f] = offset_[f] = offset_rate_[f] = knee_direction_[f] = glm::vec3(0.0f);
    anchor_yaw_[f] = yaw_offset_[f] = yaw_rate_[f] = 0.0f;
    steps_[f] = Step{};
  }
  hip_drop_[b] = hip_drop_rate_[b] = hip_goal_[b] = 0.0f;
}

void FootLocker::reset(std::uint32_t b) {
  assert(b < characters_);
  clear(b);
}

void FootLocker::step(std::uint32_t b, std::size_t side) {
  assert(b < characters_ && side < 2);
  const std::size_t f = std::size_t{b} * 2 + side;
  if (stepping(b, side)) return;
  locked_[f] = 0;
  steps_[f] = Step{0.0f, 0.0f, yaw_offset_[f], offset_[f]};
}

namespace {

glm::vec3 contact_at(const glm::vec3& ankle, const glm::vec3& toe, std::uint8_t contact_point) {
  return contact_point == kToe ? toe : ankle;
}

}  // namespace

// update()'s steps, per foot f = 2 b + side, with the locker they update.
struct FootLocker::Steps {
  // One foot as animated this tick, with what its lock reads.
  struct FootView {
    glm::vec3 ankle{}, toe{};  // world positions, metres (toe = ankle without a toe joint)
    bool planted = false;
    std::uint8_t point = 0;  // the contact point the data names: heel 0 or toe 1
    bool has_yaw = false;    // the foot's heading is read and not vertical
    float yaw = 0.0f;        // that heading, radians
  };
  // Where the IK puts one ankle, and the foot's world rotation there.
  struct FootTarget {
    glm::vec3 ankle{};
    glm::quat rotation{};
    bool solve = false;
  };
  static FootView view_foot(FootLocker& l, std::size_t f, std::size_t side, std::uint8_t contacts,
                            const glm::vec3* world, const glm::quat* global);
  static bool move_point(FootLocker& l, std::size_t f, const FootView& foot, std::uint8_t to);
  static void hold_lock(FootLocker& l, std::size_t f, const FootView& foot, float dt);
  static void update_lock(FootLocker& l, std::size_t f, const FootView& foot, float dt);
  static void update_step(FootLocker& l, std::size_t f, float dt);
  static FootTarget foot_target(FootLocker& l, std::size_t f, std::size_t side, const FootView& foot,
                                const glm::vec3& root_position, const glm::quat* global);
  static float wanted_hip_drop(FootLocker& l, std::size_t side, const FootTarget& target, const glm::vec3* world);
  static float lower_hips(FootLocker& l, std::uint32_t b, float dt, float wanted_drop, const glm::quat& root,
                          const glm::quat* global, glm::vec3* translations, glm::vec3* world);
  static void solve_leg(FootLocker& l, std::size_t f, std::size_t side, const FootTarget& target, const glm::vec3& pole,
                        const glm::quat& root, glm::quat* global, glm::quat* rotations, const glm::vec3* translations,
                        glm::vec3* world);
};

void FootLocker::update(std::uint32_t b, float dt, std::uint8_t contacts, const glm::vec3& root_position,
                        float root_yaw, std::span<const glm::vec3> animated_world,
                        std::span<glm::quat> local_rotations, std::span<glm::vec3> local_translations,
                        std::span<glm::vec3> world_positions) {
  const std::size_t joints = parents_.size();
  assert(b < characters_ && local_rotations.size() >= joints && local_translations.size() >= joints &&
         world_positions.size() >= joints && animated_world.size() >= joints && dt >= 0.0f);
  glm::quat stack[kStackJoints];
  glm::quat* global = joints <= kStackJoints ? stack : wide_scratch_.data() + std::size_t{b} * joints;
  glm::quat* rotations = local_rotations.data();
  glm::vec3* translations = local_translations.data();
  glm::vec3* world = world_positions.data();

  // The animated pose's world positions come in (the caller's forward
  // kinematics); the legs need the global rotations of their chains only.
  std::copy(animated_world.begin(), animated_world.begin() + std::ptrdiff_t(joints), world);
  const glm::quat root = yaw_rotation(root_yaw);
  for (const int joint : rotated_joints_) {
    const std::size_t j = static_cast<std::size_t>(joint);
    const int parent = parents_[j];
    global[j] = (parent < 0 ? root : global[static_cast<std::size_t>(parent)]) * rotations[j];
  }
  if (!params_.enabled) {
    clear(b);
    return;
  }

  // Per foot: the lock's state machine, then its ankle target and rotation.
  Steps::FootTarget targets[2];
  float wanted_drop = 0.0f;
  for (std::size_t side = 0; side < 2; ++side) {
    const std::size_t f = std::size_t{b} * 2 + side;
    const Steps::FootView foot = Steps::view_foot(*this, f, side, contacts, world, global);
    Steps::update_lock(*this, f, foot, dt);
    targets[side] = Steps::foot_target(*this, f, side, foot, root_position, global);
    if (targets[side].solve)
      wanted_drop = std::max(wanted_drop, Steps::wanted_hip_drop(*this, side, targets[side], world));
  }
  const float drop = Steps::lower_hips(*this, b, dt, wanted_drop, root, global, translations, world);

  // Two-bone IK on each leg that has a correction (both when the hips are
  // lowered: the other foot must stay where it was animated). The knee bends
  // toward its kept direction (follow_knee), kept on every tick so that it
  // is current when a solve starts.
  for (std::size_t side = 0; side < 2; ++side) {
    const std::size_t f = std::size_t{b} * 2 + side;
    clamped_[f] = 0;
    const Leg& leg = legs_[side];
    const bool solve = targets[side].solve || drop > 0.0f;
    const glm::vec3 pole =
        follow_knee(knee_direction_[f], world[leg.upper], world[leg.lower], world[leg.foot], root, dt, solve);
    if (!solve) continue;
    Steps::solve_leg(*this, f, side, targets[side], pole, root, global, rotations, translations, world);
  }
}

FootLocker::Steps::FootView FootLocker::Steps::view_foot(FootLocker& l, std::size_t f, std::size_t side,
                                                         std::uint8_t contacts, const glm::vec3* world,
                                                         const glm::quat* global) {
  const Leg& leg = l.legs_[side];
  FootView foot;
  foot.ankle = world[leg.foot];
  foot.toe = leg.toe >= 0 ? world[leg.toe] : foot.ankle;
  foot.planted = (contacts & kPlantedBit[side]) != 0;
  const bool toe_touches = (contacts & kToeBit[side]) != 0;
  const bool heel_touches = (contacts & kHeelBit[side]) != 0;
  // Data without point bits (older files) counts as planted on the toe.
  foot.point = leg.toe >= 0 && (toe_touches || !heel_touches) ? kToe : kHeel;
  // The foot's heading, only where a lock reads it.
  foot.has_yaw = l.params_.lock_yaw && (foot.planted || l.locked_[f] != 0) &&
                 heading_yaw(global[leg.foot] * l.heading_[side], foot.yaw);
  return foot;
}

// A new contact point keeps the displayed foot where it is: the offset takes
// up the turn of the new point about the old one.
bool FootLocker::Steps::move_point(FootLocker& l, std::size_t f, const FootView& foot, std::uint8_t to) {
  if (to == l.point_[f]) return false;
  const glm::vec3 step = contact_at(foot.ankle, foot.toe, to) - contact_at(foot.ankle, foot.toe, l.point_[f]);
  l.offset_[f] += horizontal(yaw_rotation(l.yaw_offset_[f]) * step - step);
  l.point_[f] = to;
  return true;
}

// A locked, planted foot: the offsets that hold its contact point on the
// anchor, or the release when the animation walked it too far away.
void FootLocker::Steps::hold_lock(FootLocker& l, std::size_t f, const FootView& foot, float dt) {
  glm::vec3& offset = l.offset_[f];
  float& yaw_offset = l.yaw_offset_[f];
  // Heel to toe (or back): the anchor moves to the new point as shown.
  if (move_point(l, f, foot, foot.point)) l.anchor_[f] = contact_at(foot.ankle, foot.toe, l.point_[f]) + offset;
  if (!foot.has_yaw) {
    l.anchor_yaw_[f] = kNoYaw;
  } else if (std::isnan(l.anchor_yaw_[f])) {
    l.anchor_yaw_[f] = foot.yaw + yaw_offset;
  }
  const glm::vec3 next = horizontal(l.anchor_[f] - contact_at(foot.ankle, foot.toe, l.point_[f]));
  float next_yaw = foot.has_yaw ? wrap_angle(l.anchor_yaw_[f] - foot.yaw) : yaw_offset;
  if (std::abs(next_yaw) > l.params_.max_yaw_correction) {
    // The animated foot turned further than the lock holds: it pivots
    // about its contact point from here, the position still held.
    next_yaw = std::clamp(next_yaw, -l.params_.max_yaw_correction, l.params_.max_yaw_correction);
    l.anchor_yaw_[f] = foot.yaw + next_yaw;
  }
  if (glm::length(next) > l.params_.unlock_distance) {
    l.locked_[f] = 0;
    l.drifted_[f] = 1;
  } else {
    if (dt > 0.0f) {
      l.offset_rate_[f] = (next - offset) / dt;
      l.yaw_rate_[f] = wrap_angle(next_yaw - yaw_offset) / dt;
    }
    offset = next;
    yaw_offset = next_yaw;
  }
}

// The lock's state machine: held while planted, taken where the foot is
// shown when it plants, and its offsets decaying after release.
void FootLocker::Steps::update_lock(FootLocker& l, std::size_t f, const FootView& foot, float dt) {
  if (l.steps_[f].time >= 0.0f) {
    update_step(l, f, dt);
    return;
  }
  if (!foot.planted) l.drifted_[f] = 0;
  if (l.locked_[f] != 0) {
    if (!foot.planted) {
      l.locked_[f] = 0;
    } else {
      hold_lock(l, f, foot, dt);
    }
  }
  if (l.locked_[f] != 0) return;
  glm::vec3& offset = l.offset_[f];
  glm::vec3& offset_rate = l.offset_rate_[f];
  float& yaw_offset = l.yaw_offset_[f];
  float& yaw_rate = l.yaw_rate_[f];
  if (foot.planted && l.drifted_[f] == 0) {
    // Lock where the foot is shown now: the offset carries on, so does the
    // display.
    move_point(l, f, foot, foot.point);
    l.locked_[f] = 1;
    l.anchor_[f] = contact_at(foot.ankle, foot.toe, l.point_[f]) + offset;
    l.anchor_yaw_[f] = foot.has_yaw ? foot.yaw + yaw_offset : kNoYaw;
  } else if (dt > 0.0f) {
    spring_decay(offset, offset_rate, l.params_.release_half_life, dt);
    spring_decay(yaw_offset, yaw_rate, l.params_.release_half_life, dt);
    if (glm::length(offset) < kSettled && glm::length(offset_rate) < kSettledRate) {
      offset = offset_rate = glm::vec3(0.0f);
    }
    if (std::abs(yaw_offset) < kSettled && std::abs(yaw_rate) < kSettledRate) yaw_offset = yaw_rate = 0.0f;
  }
}

// A step (step()): the offsets ease from where it started to zero over
// kStepSeconds (smoothstep, so the foot leaves and lands at rest), the foot
// raised on a half sine of kStepHeightRatio times the distance, at most
// kMaxStepHeight. On arrival the foot is on its animated pose, unlocked: a
// planted foot locks there on its next update.
void FootLocker::Steps::update_step(FootLocker& l, std::size_t f, float dt) {
  Step& step = l.steps_[f];
  step.time = std::min(step.time + dt, kStepSeconds);
  const float t = step.time / kStepSeconds;
  const float eased = t * t * (3.0f - 2.0f * t);
  const float eased_rate = 6.0f * t * (1.0f - t) / kStepSeconds;
  l.offset_[f] = step.from * (1.0f - eased);
  l.offset_rate_[f] = -step.from * eased_rate;
  l.yaw_offset_[f] = step.from_yaw * (1.0f - eased);
  l.yaw_rate_[f] = -step.from_yaw * eased_rate;
  step.lift = std::min(kMaxStepHeight, kStepHeightRatio * glm::length(step.from)) * std::sin(kPi * t);
  if (step.time >= kStepSeconds) {
    step = Step{};
    l.offset_[f] = l.offset_rate_[f] = glm::vec3(0.0f);
    l.yaw_offset_[f] = l.yaw_rate_[f] = 0.0f;
    l.drifted_[f] = 0;
  }
}

// The ankle's target: the animated foot turned by the yaw offset about its
// contact point and moved by the offset, at its animated height (raised to
// the floor when clamped).
FootLocker::Steps::FootTarget FootLocker::Steps::foot_target(FootLocker& l, std::size_t f, std::size_t side,
                                                             const FootView& foot, const glm::vec3& root_position,
                                                             const glm::quat* global) {
  const Leg& leg = l.legs_[side];
  FootTarget target;
  target.ankle = foot.ankle;
  target.rotation = global[leg.foot];
  target.solve = false;
  if (l.offset_[f] != glm::vec3(0.0f) || l.yaw_offset_[f] != 0.0f) {
    const glm::vec3 contact = contact_at(foot.ankle, foot.toe, l.point_[f]);
    const glm::quat turn = yaw_rotation(l.yaw_offset_[f]);
    target.ankle = contact + l.offset_[f] + turn * (foot.ankle - contact);
    target.rotation = turn * global[leg.foot];
    target.solve = true;
  }
  if (l.steps_[f].lift > 0.0f) {
    target.ankle.y += l.steps_[f].lift;
    target.solve = true;
  }
  if (l.params_.clamp_to_floor) {
    // The turn is about +Y, so the toe stays at its animated height above the ankle.
    const float floor = root_position.y + l.params_.floor_height;
    const float lowest = std::min(target.ankle.y, target.ankle.y + (foot.toe.y - foot.ankle.y));
    if (lowest < floor) {
      target.ankle.y += floor - lowest;
      target.solve = true;
    }
  }
  return target;
}

// The least drop of the hips that brings a solved target within the leg's
// comfortable reach (the solver's soft start): |target - (hip - drop * up)|
// = reach, the smaller root; the drop to the target's height when the target
// is horizontally further than the reach; 0 within reach. An animated target
// needs none: the animated extension is within reach by definition.
float FootLocker::Steps::wanted_hip_drop(FootLocker& l, std::size_t side, const FootTarget& target,
                                         const glm::vec3* world) {
  const Leg& leg = l.legs_[side];
  const glm::vec3 ankle = world[leg.foot];
  const glm::vec3 hip = world[leg.upper];
  const float length = glm::length(world[leg.lower] - hip) + glm::length(ankle - world[leg.lower]);
  const float reach = std::min(length, std::max(l.params_.soft_reach_start * length, glm::length(ankle - hip)));
  const glm::vec3 to_target = target.ankle - hip;
  const float across2 = to_target.x * to_target.x + to_target.z * to_target.z;
  if (across2 + to_target.y * to_target.y <= reach * reach) return 0.0f;
  return across2 < reach * reach ? -to_target.y - std::sqrt(reach * reach - across2) : -to_target.y;
}

// The hips follow the wanted drop with a critically damped spring; returns
// the drop applied (metres, >= 0).
float FootLocker::Steps::lower_hips(FootLocker& l, std::uint32_t b, float dt, float wanted_drop, const glm::quat& root,
                                    const glm::quat* global, glm::vec3* translations, glm::vec3* world) {
  float& drop = l.hip_drop_[b];
  float& drop_rate = l.hip_drop_rate_[b];
  const float goal = std::min(wanted_drop, l.params_.max_hip_drop);
  if (dt > 0.0f) {
    // The spring follows the goal as it moved since the last tick, at up to
    // max_hip_goal_rate: a goal that deepens steadily (a stride stretching)
    // is followed without the spring's lag, which let the held foot slip out
    // of reach; a faster change (a step) is left to the spring to smooth.
    float& last_goal = l.hip_goal_[b];
    const float goal_rate =
        std::clamp((goal - last_goal) / dt, -l.params_.max_hip_goal_rate, l.params_.max_hip_goal_rate);
    float gap = drop - last_goal;
    float gap_rate = drop_rate - goal_rate;
    spring_decay(gap, gap_rate, l.params_.hip_half_life, dt);
    drop = std::clamp(last_goal + goal_rate * dt + gap, 0.0f, l.params_.max_hip_drop);
    drop_rate = goal_rate + gap_rate;
    last_goal = goal;
    if (goal == 0.0f && drop < kSettled && std::abs(drop_rate) < kSettledRate) drop = drop_rate = 0.0f;
  }
  if (drop > 0.0f) {
    const int parent = l.parents_[static_cast<std::size_t>(l.hips_)];
    const glm::quat above = parent < 0 ? root : global[static_cast<std::size_t>(parent)];
    translations[static_cast<std::size_t>(l.hips_)] -= glm::inverse(above) * (kUp * drop);
    for (std::size_t j = 0; j < l.parents_.size(); ++j) {
      if (l.below_hips_[j] != 0) world[j].y -= drop;
    }
  }
  return drop;
}

// Two-bone IK on one leg, then the leg's joints again from the upper leg down.
void FootLocker::Steps::solve_leg(FootLocker& l, std::size_t f, std::size_t side, const FootTarget& target,
                                  const glm::vec3& pole, const glm::quat& root, glm::quat* global, glm::quat* rotations,
                                  const glm::vec3* translations, glm::vec3* world) {
  const Leg& leg = l.legs_[side];
  const TwoBoneIkSolution solution = solve_two_bone_ik_toward(world[leg.upper], world[leg.lower], world[leg.foot],
                                                              target.ankle, pole, l.params_.soft_reach_start);
  l.clamped_[f] = solution.clamped ? 1 : 0;
  for (const int joint : l.leg_joints_[side]) {
    const std::size_t j = static_cast<std::size_t>(joint);
    const int parent = l.parents_[j];
    const glm::quat above = parent < 0 ? root : global[static_cast<std::size_t>(parent)];
    if (joint == leg.upper) {
      global[j] = solution.upper * global[j];
    } else {
      world[j] = world[static_cast<std::size_t>(parent)] + above * translations[j];
      if (joint == leg.lower) {
        global[j] = solution.lower * (above * rotations[j]);
      } else if (joint == leg.foot) {
        global[j] = target.rotation;
      } else {
        global[j] = above * rotations[j];
        continue;
      }
    }
    rotations[j] = glm::normalize(glm::inverse(above) * global[j]);
  }
}

}  // namespace mmvk
