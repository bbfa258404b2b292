// The controller's gait from the command (ControllerParams::choose_gait,
// gait_choice.hpp): per character, the state and the tag constraint of its
// searches, and the rest on a held frame where the data has no idle.
#include <cmath>
#include <limits>

#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/animation/foot_locker.hpp"
#include "mmvk/animation/playback.hpp"
#include "mmvk/features/foot_contacts.hpp"
#include "mmvk/search/search.hpp"
#include "play_rate.hpp"
#include "rest_frames.hpp"

namespace mmvk {

namespace {

// Distinct pairs of masks kept; beyond (a host that gives its characters
// ever new tags) the entries start anew with only those in use.
constexpr std::size_t kMaxGaitEntries = 256;
constexpr std::uint32_t kNoEntry = std::numeric_limits<std::uint32_t>::max();

// Whether the standing frames of `frame`'s clip from `frame` on (tagged
// `stand`) end, with the clip or in a frame that moves, without one that
// has both feet down.
bool steps_off_standing(const Database& database, TagMask stand, std::uint32_t frame) {
  const Clip& clip = database.clips()[database.frame_clip()[frame]];
  for (std::uint32_t f = frame; f < clip.first_frame + clip.frame_count && (database.frame_tags()[f] & stand) != 0;
       ++f) {
    if (both_feet_planted(database.animation()->contacts[f])) return false;
  }
  return true;
}

}  // namespace

void CrowdController::start_gaits() {
  const GaitBandParams* params = database_->gait_bands();
  gaits_.enabled = params_.choose_gait && params != nullptr;
  if (!gaits_.enabled) return;
  gaits_.params = *params;
  gaits_.bits = gait_tag_bits(*database_);
  gaits_.entries.clear();
  gaits_.entry.assign(characters_, gait_entry(0, 0));
}

std::uint32_t CrowdController::gait_entry(TagMask require, TagMask exclude) {
  for (std::size_t i = 0; i < gaits_.entries.size(); ++i) {
    if (gaits_.entries[i].require == require && gaits_.entries[i].exclude == exclude) return std::uint32_t(i);
  }
  Gaits::Entry e;
  e.require = require;
  e.exclude = exclude;
  e.options = gait_options(measure_gait_coverage(*database_, require, exclude));
  e.rest_frames = detail::find_rest_frames(*database_, stride_speeds_, require, exclude);
  gaits_.entries.push_back(std::move(e));
  return std::uint32_t(gaits_.entries.size() - 1);
}

void CrowdController::refresh_gait_options() {
  if (!gaits_.enabled) return;
  if (gaits_.entries.size() > kMaxGaitEntries) {
    gaits_.entries.clear();
    std::fill(gaits_.entry.begin(), gaits_.entry.end(), kNoEntry);
  }
  for (std::uint32_t b = 0; b < characters_; ++b) {
    const QueryParams& own = schedule_.query_params[b];
    if (gaits_.entry[b] != kNoEntry && own.require_all == gaits_.own_require[b] &&
        own.exclude_any == gaits_.own_exclude[b]) {
      continue;
    }
    gaits_.own_require[b] = own.require_all;
    gaits_.own_exclude[b] = own.exclude_any;
    gaits_.own_gait[b] = ((own.require_all | own.exclude_any) & gaits_.bits.all) != 0 ? 1 : 0;
    gaits_.entry[b] = gait_entry(own.require_all, own.exclude_any);
  }
}

bool CrowdController::choose_gait(std::size_t b, float dt, ThreadScratch& scratch) {
  if (!gaits_.enabled) return false;
  const float commanded = detail::horizontal_speed(schedule_.desired_velocity[b]);
  const float simulated = detail::horizontal_speed(roots_.simulated[b].velocity);
  GaitState& state = gaits_.state[b];
  state = gaits_.first[b] ? first_gait_state(gaits_.params, commanded)
                          : next_gait_state(gaits_.params, state, commanded, simulated, dt);
  gaits_.first[b] = 0;
  const Gaits::Entry& entry = gaits_.entries[gaits_.entry[b]];
  const GaitConstraint constraint =
      gaits_.own_gait[b] ? GaitConstraint{} : gait_constraint(state, entry.options, gaits_.bits);
  // New frames are allowed or the old ones forbidden: search now, not at
  // the next regular search.
  if (!(constraint == gaits_.constraint[b])) schedule_.force[b] = 1;
  gaits_.constraint[b] = constraint;

  std::uint8_t& holding = gaits_.holding[b];
  if (state.phase != GaitPhase::Stand || gaits_.own_gait[b]) {
    holding = 0;
    return false;
  }
  if (holding) return true;
  // From the tick it holds, its simulated root waits where the animation
  // brought the body: the correction would glide it, feet and all, to
  // wherever the spring stopped. A host that holds a position still draws
  // it there (its velocities move the simulated root again).
  const auto settle = [&] {
    roots_.simulated[b].position = roots_.position[b];
    return true;
  };
  const std::uint32_t frame = playback_.frames[b];
  const std::uint32_t clip = database_->frame_clip()[frame];
  // The rest frame of the clip it plays, blended into by the
  // inertialization as any jump is, then held (its feet locked).
  const auto rest = [&] {
    const std::uint32_t to = entry.rest_frames[clip];
    if (to == kNoFrame) return false;
    if (to != frame) jump(static_cast<std::uint32_t>(b), to, scratch);
    holding = 1;
    return settle();
  };
  if (constraint.rest) return rest();  // no idle
  // Standing frames of a clip that goes on (a walk's first steps, a stop's
  // end) are held once both feet are down: played on they would shift
  // weight and step off, and each search would cut that short. One whose
  // standing frames step off before both feet are down (a weight shift
  // into a start) would never be held: each search would pick another,
  // and the character shuffle. It rests instead.
  const TagMask stand = gaits_.bits.bit[std::size_t(GaitBand::Stand)];
  if (database_->clips()[clip].loop || (database_->frame_tags()[frame] & stand) == 0) return false;
  if (both_feet_planted(animation_->contacts[frame])) {
    holding = 1;
    return settle();
  }
  return steps_off_standing(*database_, stand, frame) && rest();
}

void CrowdController::settle_feet(std::uint32_t b) {
  // Held where it planted mid-stride, a foot would stay a stride from the
  // standing pose (legs stretched, hips lowered) for as long as the
  // character stands: such a foot steps onto its pose (FootLocker::step),
  // one foot at a time and the farther first. The foot it lifts is shown
  // off the ground. Standing, the distance is just above the 10 cm a
  // planted toe may be off its pose, so that a foot near it stays put and
  // the stand still.
  constexpr float kStandingStepDistance = 0.11f;  // metres
  // Moving, a lock holds a foot off its pose when a jump's blend or the
  // correction moves the pose under it (up to 41 cm in a 180-degree turn on
  // Bandai: the leg stretched behind, across the other, sliding where it
  // cannot reach); such a foot steps once it is 10 cm off.
  constexpr float kMovingStepDistance = 0.10f;  // metres
  if (!locker_) return;
  const bool standing = gaits_.enabled && gaits_.state[b].phase == GaitPhase::Stand;
  const float step_distance = standing ? kStandingStepDistance : kMovingStepDistance;
  const auto off_pose = [&](std::size_t side) {
    const glm::vec3& c = locker_->corrections()[std::size_t{b} * 2 + side];
    return locker_->locked()[std::size_t{b} * 2 + side] != 0 ? std::hypot(c.x, c.z) : 0.0f;
  };
  if (!locker_->stepping(b, 0) && !locker_->stepping(b, 1)) {
    const std::size_t farther = off_pose(1) > off_pose(0) ? 1 : 0;
    if (off_pose(farther) > step_distance) locker_->step(b, farther);
  }
  for (std::size_t side = 0; side < 2; ++side) {
    if (!locker_->stepping(b, side)) continue;
    const int s = int(side);
    playback_.contacts[b] &= std::uint8_t(~(contact_planted_bit(s) | contact_heel_bit(s) | contact_toe_bit(s)));
  }
}

}  // namespace mmvk
