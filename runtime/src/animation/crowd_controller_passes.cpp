// The passes of a controller tick (crowd_controller.hpp, steps 1-8), each
// over all characters (or all of the batch), in the order the header numbers
// them.
#include <algorithm>
#include <cmath>

#include "character_ranges.hpp"
#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/animation/playback.hpp"
#include "mmvk/animation/spring.hpp"
#include "play_rate.hpp"
#include "pose_velocity.hpp"
#include "root_correction.hpp"
#include "shown_pose.hpp"
#include "yaw.hpp"

namespace mmvk {

using detail::for_characters;

namespace {

// Steps 1-4 run block by block within a thread's characters: each step is a
// pass over the block, whose state is still in cache for the next step.
constexpr std::size_t kBlock = 64;

}  // namespace

void CrowdController::advance(float dt, const CrowdInput& input, ThreadPool& pool) {
  refresh_gait_options();
  const float fraction = 1.0f - std::exp2(-dt / params_.correction_half_life);
  for_characters(pool, characters_, [&](std::size_t begin, std::size_t end, unsigned thread) {
    for (std::size_t first = begin; first < end; first += kBlock) {
      const std::size_t last = std::min(end, first + kBlock);
      simulate_and_play(first, last, dt, input, scratch_[thread]);  // 1
      blend(first, last, dt);                     // 2
      correct(first, last, dt, fraction);         // 3
      decide(first, last, dt);                    // 4
    }
  });
  // Compaction in character order: the batch order is deterministic.
  batch_.count = 0;
  last_.forced = 0;
  for (std::uint32_t b = 0; b < characters_; ++b) {
    if (schedule_.due[b] == SearchKind::None) continue;
    last_.forced += schedule_.due[b] == SearchKind::Forced ? 1 : 0;
    batch_.characters[batch_.count++] = b;
  }
  last_.searches = batch_.count;
}

// 1. The simulated root follows the input; the character's time moves on.
void CrowdController::simulate_and_play(std::size_t begin, std::size_t end, float dt, const CrowdInput& input,
                                        ThreadScratch& scratch) {
  const Database& database = *database_;
  const auto flags = database.frame_flags();
  for (std::size_t b = begin; b < end; ++b) {
    schedule_.searched[b] = SearchKind::None;
    glm::vec3& desired = schedule_.desired_velocity[b];
    float& desired_yaw = schedule_.desired_yaw[b];
    desired = input.desired_velocity[b];
    desired_yaw = input.desired_yaw.empty() ? yaw_of_velocity(desired, desired_yaw) : wrap_angle(input.desired_yaw[b]);
    simulate_step(roots_.simulated[b], desired, desired_yaw, params_.spring, dt);
    const bool holds = choose_gait(b, dt, scratch);

    const PlayTime before{playback_.frames[b], playback_.fractions[b]};
    schedule_.was_blocked[b] = (flags[nearest_frame(database, before)] & kFrameBlockTransition) != 0 ? 1 : 0;
    // The simulated root's speed is the command as the character can follow
    // it: the animation moves at it where the bounds allow.
    const float target = detail::horizontal_speed(roots_.simulated[b].velocity);
    const float stride_speed = stride_speeds_[nearest_frame(database, before)];
    detail::SpeedScale scale =
        detail::speed_scale(params_, stride_speed, target, detail::horizontal_speed(desired));
    // A character placed since the last tick holds its frame until its
    // first search has chosen what it plays: moving on a frame it was only
    // placed on would give the jump a velocity that nothing commanded.
    if (holds || poses_.fresh[b] != 0) scale = detail::SpeedScale{0.0f, 1.0f};
    playback_.rate[b] = scale.play_rate;
    playback_.stride[b] = scale.stride_scale;
    const PlaybackStep step = advance_playback(database, before, dt * database.fps() * scale.play_rate);
    playback_.frames[b] = step.time.frame;
    playback_.fractions[b] = step.time.fraction;
    playback_.held[b] = step.reached_end ? 1 : 0;
    playback_.step_translation[b] = step.root_translation * scale.stride_scale;
    playback_.step_yaw[b] = step.root_yaw;
    playback_.contacts[b] = animation_->contacts[nearest_frame(database, step.time)];
    // The root motion of the frame interval now played, as played (the
    // source velocity of a jump).
    const RootDelta velocity = root_velocity_at(database, step.time.frame);
    playback_.played_velocity[b] = velocity.translation * (scale.play_rate * scale.stride_scale);
    playback_.played_yaw_rate[b] = velocity.yaw * scale.play_rate;
  }
}

// 2. The pose at the character's time plus the decaying offsets; the root
// moves along the clip's path plus the root offset.
void CrowdController::blend(std::size_t begin, std::size_t end, float dt) {
  for (std::size_t b = begin; b < end; ++b) {
    const std::uint32_t frame = playback_.frames[b];
    const std::size_t base = b * joints_;
    const std::span<glm::quat> rotations(poses_.animated_rotations.data() + base, joints_);
    const std::span<glm::vec3> translations(poses_.animated_translations.data() + base, joints_);
    sample_pose_at(*animation_, frame, next_frame(*database_, frame), playback_.fractions[b], rotations, translations);
    const Inertializer::RootOffset offset = inertializer_.update(static_cast<std::uint32_t>(b),
                                                                 params_.inertialization_half_life, dt, rotations,
                                                                 translations);
    float& yaw = roots_.yaw[b];
    roots_.start_yaw[b] = yaw;
    const glm::vec3 step = playback_.step_translation[b] + offset.velocity * dt;
    roots_.animated_speed[b] = detail::horizontal_speed(step) / dt;
    roots_.position[b] += detail::yaw_rotate(step, yaw);
    roots_.position[b].y = 0.0f;
    yaw = wrap_angle(yaw + playback_.step_yaw[b] + offset.yaw_rate * dt);
  }
}

// 3. The root pulled toward the simulated one, its path recorded, and the
// animated pose measured.
void CrowdController::correct(std::size_t begin, std::size_t end, float dt, float fraction) {
  for (std::size_t b = begin; b < end; ++b) {
    const glm::vec3 animated = roots_.position[b];
    detail::correct_root(params_, dt, fraction, roots_.animated_speed[b], roots_.simulated[b], roots_.position[b],
                         roots_.yaw[b]);
    roots_.correction[b] = roots_.position[b] - animated;
    roots_.yaw_rate[b] = wrap_angle(roots_.yaw[b] - roots_.start_yaw[b]) / dt;
    const auto character = static_cast<std::uint32_t>(b);
    roots_.history.record(character, dt, roots_.position[b], roots_.yaw[b]);
    measure(character, dt, poses_.fresh[b] != 0);
  }
}

void CrowdController::measure(std::uint32_t b, float dt, bool fresh) {
  const std::size_t base = std::size_t{b} * joints_;
  const std::span<glm::vec3> world = std::span(poses_.animated_world).subspan(base, joints_);
  forward_kinematics_batch(animation_->skeleton, std::span(poses_.animated_rotations).subspan(base, joints_),
                           std::span(poses_.animated_translations).subspan(base, joints_), {&roots_.position[b], 1},
                           {&roots_.yaw[b], 1}, world);
  const std::span<const int> joints = assembler_.velocity_joints();
  const std::size_t at = std::size_t{b} * joints.size();
  detail::measure_joint_velocities(world, joints, roots_.yaw[b], dt, fresh,
                                   std::span(poses_.velocity_world).subspan(at, joints.size()),
                                   std::span(poses_.joint_velocities).subspan(at, joints.size()));
  poses_.fresh[b] = fresh && !(dt > 0.0f) ? 1 : 0;
}

// 4. Due when the timer runs out or a search is forced.
void CrowdController::decide(std::size_t begin, std::size_t end, float dt) {
  const auto flags = database_->frame_flags();
  for (std::size_t b = begin; b < end; ++b) {
    float& timer = schedule_.timer[b];
    timer -= dt;
    bool regular = false;
    // A character holding its rest frame has nothing to search for until
    // its command changes (which forces a search).
    if (timer <= 0.0f && gaits_.holding[b] == 0) {
      regular = true;
      timer = std::max(timer + params_.search_interval, 0.0f);
    }
    const std::uint32_t frame_flags =
        flags[nearest_frame(*database_, {playback_.frames[b], playback_.fractions[b]})];
    const bool forced =
        schedule_.force[b] != 0 || playback_.held[b] != 0 || (frame_flags & kFrameDoNotUse) != 0 ||
        ((frame_flags & kFrameBlockTransition) != 0 && schedule_.was_blocked[b] == 0) ||
        glm::length(schedule_.desired_velocity[b] - schedule_.searched_velocity[b]) >
            params_.force_search_velocity_change ||
        std::abs(wrap_angle(schedule_.desired_yaw[b] - schedule_.searched_yaw[b])) > params_.force_search_yaw_change;
    // A forced search leaves the regular schedule alone: resetting the timer
    // would bunch characters forced together (all of them on the first tick)
    // onto the same later ticks.
    schedule_.due[b] = forced ? SearchKind::Forced : regular ? SearchKind::Regular : SearchKind::None;
    schedule_.force[b] = 0;
  }
}

// 5. The batch's queries, from each due character's prediction and its
// animated pose.
void CrowdController::assemble(ThreadPool& pool) {
  const std::uint32_t dims = database_->dims();
  const std::span<const float> offsets = assembler_.trajectory_offsets();
  const std::span<const float> past = assembler_.past_offsets();
  const std::size_t velocity_joints = assembler_.velocity_joints().size();
  const std::size_t t = trajectory_size_;
  for_characters(pool, batch_.count, [&](std::size_t begin, std::size_t end, unsigned thread) {
    ThreadScratch& scratch = scratch_[thread];
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t b = batch_.characters[i];
      const std::span<glm::vec3> positions(schedule_.predicted_positions.data() + b * t, t);
      const std::span<float> yaws(schedule_.predicted_yaws.data() + b * t, t);
      predict_trajectory(roots_.simulated[b], schedule_.desired_velocity[b], schedule_.desired_yaw[b], params_.spring,
                         offsets, positions, yaws);
      schedule_.searched_velocity[b] = schedule_.desired_velocity[b];
      schedule_.searched_yaw[b] = schedule_.desired_yaw[b];
      schedule_.searched[b] = schedule_.due[b];
      batch_.frames[i] = QueryFrame{roots_.position[b], roots_.yaw[b]};
      const std::uint32_t nearest = nearest_frame(*database_, {playback_.frames[b], playback_.fractions[b]});
      const std::span<glm::vec3> past_positions(batch_.past_positions.data() + i * past.size(), past.size());
      const std::span<float> past_yaws(batch_.past_yaws.data() + i * past.size(), past.size());
      for (std::size_t k = 0; k < past.size(); ++k) roots_.history.at(b, past[k], past_positions[k], past_yaws[k]);
      detail::to_character_space(std::span<const glm::vec3>(poses_.animated_world).subspan(std::size_t{b} * joints_, joints_),
                                 roots_.position[b], roots_.yaw[b], scratch.joint_positions);
      ShownPose pose;
      pose.frame = nearest;
      pose.joint_positions = scratch.joint_positions;
      pose.joint_velocities =
          std::span<const glm::vec3>(poses_.joint_velocities).subspan(b * velocity_joints, velocity_joints);
      pose.yaw_rate = roots_.yaw_rate[b];
      pose.contacts = playback_.contacts[b];
      pose.past_positions = past_positions;
      pose.past_yaws = past_yaws;
      assembler_.assemble_shown(pose, batch_.frames[i], positions, yaws,
                                std::span(batch_.queries).subspan(i * dims, dims));
      QueryParams& p = batch_.params[i];
      p = schedule_.query_params[b];
      p.require_all |= gaits_.constraint[b].require_all;
      p.exclude_any |= gaits_.constraint[b].exclude_any;
      // A character held on a non-looping clip's last frame has nothing to
      // play on: that frame gets no continuing bonus, else it wins the
      // forced search it triggers and the character searches every tick.
      p.continuing_frame = playback_.held[b] != 0 ? kNoFrame : nearest;
      p.continuing_bias = params_.continuing_bias;
      p.continuing_multiplier = params_.continuing_multiplier;
      p.exclusion_window = params_.exclusion_window;
      batch_.continuing[i] = nearest;
    }
  });
}

bool CrowdController::same_location(std::uint32_t b, std::uint32_t to) const {
  const auto frame_clip = database_->frame_clip();
  const std::uint32_t frame = playback_.frames[b];
  if (frame_clip[to] != frame_clip[frame]) return false;
  const Clip& clip = database_->clips()[frame_clip[frame]];
  // Frames from the character's time to the match, the shorter way round a loop.
  float distance = float(to) - (float(frame) + playback_.fractions[b]);
  if (clip.loop) {
    const auto length = float(clip.frame_count);
    distance = std::remainder(distance, length);
  }
  return std::abs(distance) <= params_.same_location_window * database_->fps();
}

void CrowdController::jump(std::uint32_t b, std::uint32_t to, ThreadScratch& s) {
  const Database& database = *database_;
  const AnimationData& animation = *animation_;
  const std::span<glm::quat> rotations(poses_.animated_rotations.data() + std::size_t{b} * joints_, joints_);
  const std::span<glm::vec3> translations(poses_.animated_translations.data() + std::size_t{b} * joints_, joints_);
  // Source: what the character shows now (played pose + offsets), moving at
  // the played velocities plus the offsets' own rates.
  // Both poses' velocities at the rate the character plays (rate and
  // stride carry over to the destination), so the offsets start from what
  // is shown.
  const float rate = playback_.rate[b], speed = rate * playback_.stride[b];
  detail::pose_velocity(database, animation, playback_.frames[b], s.source_angular, s.source_velocities);
  detail::scale_pose_velocity(rate, s.source_angular, s.source_velocities);
  const std::span<const glm::vec3> rotation_rates = inertializer_.rotation_offset_velocities(b);
  for (std::size_t j = 0; j < joints_; ++j) s.source_angular[j] += rotation_rates[j];
  const std::span<const glm::vec3> translation_rates = inertializer_.translation_offset_velocities(b);
  for (std::size_t t = 0; t < translation_rates.size(); ++t) {
    s.source_velocities[animation.translated_joints[t]] += translation_rates[t];
  }
  const Inertializer::RootOffset root = inertializer_.root_offset(b);
  Inertializer::PoseState source{rotations, s.source_angular, translations, s.source_velocities,
                                 playback_.played_velocity[b] + root.velocity,
                                 playback_.played_yaw_rate[b] + root.yaw_rate};
  sample_pose(animation, to, s.rotations, s.translations);
  detail::pose_velocity(database, animation, to, s.angular, s.velocities);
  detail::scale_pose_velocity(rate, s.angular, s.velocities);
  RootDelta to_root = root_velocity_at(database, to);
  to_root.translation *= speed;
  to_root.yaw *= rate;
  Inertializer::PoseState destination{s.rotations, s.angular, s.translations, s.velocities, to_root.translation,
                                      to_root.yaw};
  inertializer_.transition(b, source, destination);
  // The output this tick: the destination under the full offset, which is
  // the source pose (continuity at the jump).
  std::copy(s.rotations.begin(), s.rotations.end(), rotations.begin());
  std::copy(s.translations.begin(), s.translations.end(), translations.begin());
  (void)inertializer_.update(b, params_.inertialization_half_life, 0.0f, rotations, translations);
  playback_.played_velocity[b] = to_root.translation;
  playback_.played_yaw_rate[b] = to_root.yaw;
  playback_.frames[b] = to;
  playback_.fractions[b] = 0.0f;
  playback_.held[b] = 0;
  playback_.contacts[b] = animation.contacts[to];
  outcome_.jumped[b] = 1;
}

// 7. The matches of applied_.
void CrowdController::apply(std::span<const std::uint32_t> continuing, ThreadPool& pool) {
  const std::span<const std::uint32_t> characters = applied_characters();
  const std::span<const Match> matches = applied_matches();
  for_characters(pool, characters.size(), [&](std::size_t begin, std::size_t end, unsigned thread) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t b = characters[i];
      const Match& m = matches[i];
      outcome_.match_cost[b] = m.cost;
      // A resting character holds its frame (a deferred result submitted
      // before it came to rest does not move it).
      if (m.frame == kNoFrame || m.frame == continuing[i] || gaits_.holding[b] != 0) continue;
      if (same_location(b, m.frame)) {
        outcome_.suppressed[b] = 1;
        continue;
      }
      jump(b, m.frame, scratch_[thread]);
    }
  });
  last_.applied = static_cast<std::uint32_t>(characters.size());
  for (std::size_t i = 0; i < characters.size(); ++i) {
    last_.jumps += outcome_.jumped[characters[i]];
    last_.same_location += outcome_.suppressed[characters[i]];
    last_.no_candidate += matches[i].frame == kNoFrame ? 1 : 0;
  }
}

// 8. The displayed pose of every character.
void CrowdController::display(float dt, bool after_jumps, ThreadPool& pool) {
  for_characters(pool, characters_, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto b = static_cast<std::uint32_t>(i);
      // A jump of step 7 changed the animated pose after step 3 measured it
      // (by rounding only: the jump starts from the pose shown).
      if (after_jumps && outcome_.jumped[b] != 0) {
        const std::size_t base = std::size_t{b} * joints_;
        forward_kinematics_batch(animation_->skeleton, std::span(poses_.animated_rotations).subspan(base, joints_),
                                 std::span(poses_.animated_translations).subspan(base, joints_),
                                 {&roots_.position[b], 1}, {&roots_.yaw[b], 1},
                                 std::span(poses_.animated_world).subspan(base, joints_));
      }
      display(b, dt);
    }
  });
}

void CrowdController::display(std::uint32_t b, float dt) {
  const std::size_t base = std::size_t{b} * joints_;
  const auto at = [base](auto& v) { return v.begin() + std::ptrdiff_t(base); };
  std::copy_n(at(poses_.animated_rotations), joints_, at(poses_.rotations));
  std::copy_n(at(poses_.animated_translations), joints_, at(poses_.translations));
  const std::span<const glm::vec3> animated(poses_.animated_world.data() + base, joints_);
  const std::span<glm::vec3> world(poses_.world.data() + base, joints_);
  if (locker_) {
    settle_feet(b);
    locker_->update(b, dt, playback_.contacts[b], roots_.position[b], roots_.yaw[b], animated,
                    std::span(poses_.rotations).subspan(base, joints_),
                    std::span(poses_.translations).subspan(base, joints_), world);
  } else {
    std::copy(animated.begin(), animated.end(), world.begin());
  }
}

}  // namespace mmvk
