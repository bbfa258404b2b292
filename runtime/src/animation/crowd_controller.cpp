// The batched motion matching controller loop (crowd_controller.hpp).
#include "mmvk/crowd_controller.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mmvk/playback.hpp"
#include "mmvk/spring.hpp"

namespace mmvk {

namespace {

// Rotates a character-space vector by yaw into the world (R_y(yaw) * v).
glm::vec3 yaw_rotate(const glm::vec3& v, float yaw) {
  const float c = std::cos(yaw);
  const float s = std::sin(yaw);
  return {v.x * c + v.z * s, v.y, -v.x * s + v.z * c};
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Fractions of stagger: the golden ratio spreads any number of characters
// evenly over the interval, whatever the tick rate.
constexpr float kGolden = 0.6180339887f;

// Characters below this count run on the calling thread: waking the pool
// costs more than the work.
constexpr std::size_t kParallelMin = 128;

template <class Body>
void for_characters(ThreadPool& pool, std::size_t count, const Body& body) {
  if (count < kParallelMin || pool.thread_count() == 1) {
    body(0, count, 0u);
  } else {
    pool.parallel_for(count, body);
  }
}

// The checks of CrowdController::create on its arguments, before anything is built.
Status check_controller_params(const Database& database, std::uint32_t characters, const ControllerParams& params) {
  if (database.animation() == nullptr) return missing_animation_error("crowd controller", database.no_animation_reason());
  if (characters == 0) return make_error("crowd controller: characters must be at least 1");
  // A tick searches every due character in one call (search.hpp's kMaxBatch).
  if (characters > kMaxBatch) {
    return make_error("crowd controller: characters = " + std::to_string(characters) + " is over kMaxBatch = " +
                      std::to_string(kMaxBatch));
  }
  auto positive = [](float v) { return std::isfinite(v) && v > 0.0f; };
  const struct {
    const char* name;
    float value;
  } checks[] = {{"search_interval", params.search_interval},
                {"inertialization_half_life", params.inertialization_half_life},
                {"spring.velocity_half_life", params.spring.velocity_half_life},
                {"spring.yaw_half_life", params.spring.yaw_half_life},
                {"force_search_velocity_change", params.force_search_velocity_change},
                {"force_search_yaw_change", params.force_search_yaw_change},
                {"correction_half_life", params.correction_half_life},
                {"max_correction_speed", params.max_correction_speed},
                {"max_correction_distance", params.max_correction_distance},
                {"max_correction_yaw_rate", params.max_correction_yaw_rate},
                {"max_correction_yaw", params.max_correction_yaw}};
  for (const auto& check : checks) {
    if (!positive(check.value)) {
      return make_error(std::string("crowd controller: ") + check.name + " must be finite and > 0, got " +
                        std::to_string(check.value));
    }
  }
  if (!std::isfinite(params.continuing_bias)) return make_error("crowd controller: continuing_bias must be finite");
  if (!std::isfinite(params.continuing_multiplier) || params.continuing_multiplier < 0.0f) {
    return make_error("crowd controller: continuing_multiplier must be finite and >= 0");
  }
  if (!std::isfinite(params.same_location_window) || params.same_location_window < 0.0f) {
    return make_error("crowd controller: same_location_window must be finite and >= 0 (seconds)");
  }
  return {};
}

}  // namespace

Result<CrowdController> CrowdController::create(const Database& database, std::uint32_t characters,
                                                const ControllerParams& params) {
  MMVK_TRY(check_controller_params(database, characters, params));
  const AnimationData* animation = database.animation();
  Result<QueryAssembler> assembler = QueryAssembler::create(database);
  if (!assembler.ok()) return make_error("crowd controller: " + assembler.message());
  Result<FootLocker> locker = FootLocker::create(*animation, characters, params.foot_ik);
  if (!locker.ok() && params.foot_ik.enabled) {
    return make_error("crowd controller: " + locker.message() + " (foot_ik.enabled = false runs without foot locking)");
  }

  CrowdController c;
  c.database_ = &database;
  c.animation_ = animation;
  c.params_ = params;
  c.assembler_ = std::move(*assembler);
  c.inertializer_ = Inertializer(characters, *animation);
  c.characters_ = characters;
  c.joints_ = static_cast<std::uint32_t>(animation->joint_count());
  c.trajectory_size_ = static_cast<std::uint32_t>(c.assembler_.trajectory_offsets().size());
  const std::size_t n = characters;
  c.frames_.assign(n, 0);
  c.fractions_.assign(n, 0.0f);
  c.search_timer_.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    const float fraction = static_cast<float>(b) * kGolden;
    c.search_timer_[b] = params.search_interval * (fraction - std::floor(fraction));
  }
  c.force_.assign(n, 1);
  c.due_flag_.assign(n, 0);
  c.searched_.assign(n, 0);
  c.jumped_.assign(n, 0);
  c.suppressed_.assign(n, 0);
  c.contacts_.assign(n, animation->contacts[0]);
  c.match_cost_.assign(n, std::numeric_limits<float>::infinity());
  c.root_pos_.assign(n, glm::vec3(0.0f));
  c.root_yaw_.assign(n, 0.0f);
  c.yaw_rate_.assign(n, 0.0f);
  const std::span<const float> past = c.assembler_.past_offsets();
  c.history_ = RootHistory(characters, past.empty() ? 0.0f : *std::max_element(past.begin(), past.end()));
  c.played_velocity_.assign(n, glm::vec3(0.0f));
  c.played_yaw_rate_.assign(n, 0.0f);
  c.sim_.assign(n, SimulationState{});
  c.desired_velocity_.assign(n, glm::vec3(0.0f));
  c.searched_velocity_.assign(n, glm::vec3(0.0f));
  c.desired_yaw_.assign(n, 0.0f);
  c.searched_yaw_.assign(n, 0.0f);
  c.query_params_.assign(n, QueryParams{});
  c.pred_pos_.assign(n * c.trajectory_size_, glm::vec3(0.0f));
  c.pred_yaw_.assign(n * c.trajectory_size_, 0.0f);
  c.rotations_.resize(n * c.joints_);
  c.translations_.resize(n * c.joints_);
  c.anim_rotations_.resize(n * c.joints_);
  c.anim_translations_.resize(n * c.joints_);
  c.joint_positions_.resize(n * c.joints_);
  const std::size_t velocity_joints = c.assembler_.velocity_joints().size();
  c.velocity_world_.assign(n * velocity_joints, glm::vec3(0.0f));
  c.joint_velocities_.assign(n * velocity_joints, glm::vec3(0.0f));
  c.fresh_.assign(n, 1);
  c.held_.assign(n, 0);
  if (locker.ok()) c.locker_ = std::move(*locker);
  c.world_.resize(n * c.joints_);
  c.anim_world_.resize(n * c.joints_);
  c.no_feet_flags_.assign(2 * n, 0);
  c.no_feet_anchors_.assign(2 * n, glm::vec3(0.0f));
  c.past_pos_.resize(n * past.size());
  c.past_yaw_.resize(n * past.size());
  for (std::uint32_t b = 0; b < characters; ++b) MMVK_TRY(c.place(b, glm::vec3(0.0f), 0.0f, 0));
  c.due_.resize(n);
  c.continuing_.resize(n);
  c.due_refs_.resize(n);
  c.queries_.resize(n * database.dims());
  c.batch_params_.resize(n);
  c.matches_.resize(n);
  c.pending_.resize(n);
  c.pending_continuing_.resize(n);
  return c;
}

Status CrowdController::place(std::uint32_t b, const glm::vec3& position, float yaw, std::uint32_t frame) {
  if (b >= characters_) return make_error("crowd controller: place: character " + std::to_string(b) + " of " + std::to_string(characters_));
  if (frame >= database_->frame_count()) {
    return make_error("crowd controller: place: frame " + std::to_string(frame) + " of " +
                      std::to_string(database_->frame_count()));
  }
  if (!finite(position) || !std::isfinite(yaw)) return make_error("crowd controller: place: position and yaw must be finite");
  const glm::vec3 ground(position.x, 0.0f, position.z);
  root_pos_[b] = ground;
  root_yaw_[b] = wrap_angle(yaw);
  sim_[b] = SimulationState{};
  sim_[b].position = ground;
  sim_[b].yaw = root_yaw_[b];
  desired_velocity_[b] = searched_velocity_[b] = glm::vec3(0.0f);
  desired_yaw_[b] = searched_yaw_[b] = root_yaw_[b];
  frames_[b] = frame;
  fractions_[b] = 0.0f;
  held_[b] = 0;
  force_[b] = 1;
  played_velocity_[b] = glm::vec3(0.0f);
  played_yaw_rate_[b] = 0.0f;
  yaw_rate_[b] = 0.0f;
  inertializer_.reset(b);
  history_.reset(b, ground, root_yaw_[b]);
  contacts_[b] = animation_->contacts[frame];
  const std::size_t base = std::size_t{b} * joints_;
  sample_pose(*animation_, frame, std::span(anim_rotations_).subspan(base, joints_),
              std::span(anim_translations_).subspan(base, joints_));
  measure_shown(b, 0.0f, true);
  if (locker_) locker_->reset(b);
  display(b, 0.0f);
  return {};
}

Status CrowdController::check_input(float dt, const CrowdInput& input) const {
  if (!std::isfinite(dt) || !(dt > 0.0f)) return make_error("crowd controller: dt must be finite and > 0, got " + std::to_string(dt));
  if (input.desired_velocity.size() != characters_) {
    return make_error("crowd controller: desired_velocity has " + std::to_string(input.desired_velocity.size()) +
                      " entries, expected one per character (" + std::to_string(characters_) + ")");
  }
  if (!input.desired_yaw.empty() && input.desired_yaw.size() != characters_) {
    return make_error("crowd controller: desired_yaw has " + std::to_string(input.desired_yaw.size()) +
                      " entries, expected none or one per character (" + std::to_string(characters_) + ")");
  }
  for (std::uint32_t b = 0; b < characters_; ++b) {
    if (!finite(input.desired_velocity[b])) {
      return make_error("crowd controller: desired_velocity of character " + std::to_string(b) + " is not finite");
    }
    if (!input.desired_yaw.empty() && !std::isfinite(input.desired_yaw[b])) {
      return make_error("crowd controller: desired_yaw of character " + std::to_string(b) + " is not finite");
    }
  }
  return {};
}

void CrowdController::ensure_scratch(unsigned threads) {
  // Grows only when a larger pool is first seen: no allocation in steady state.
  if (scratch_.size() >= threads) return;
  scratch_.resize(threads);
  for (JumpScratch& s : scratch_) {
    s.rotations.resize(joints_);
    s.translations.resize(joints_);
    s.angular.resize(joints_);
    s.velocities.resize(joints_);
    s.source_angular.resize(joints_);
    s.source_velocities.resize(joints_);
  }
}

namespace {

// The frames a finite difference at `frame` uses: forward inside its clip,
// backward on its last frame; {frame, frame} for a one-frame clip.
std::pair<std::uint32_t, std::uint32_t> difference_frames(const Database& database, std::uint32_t frame) {
  const Clip& clip = database.clips()[database.frame_clip()[frame]];
  if (frame + 1 < clip.first_frame + clip.frame_count) return {frame, frame + 1};
  if (frame > clip.first_frame) return {frame - 1, frame};
  return {frame, frame};
}

// The rotation vector of one frame's rotation step. Steps are small (under
// 0.2 rad at 30 fps for human motion), where 2 v / w (the tangent of the half
// angle) is within 0.4% of the angle and needs no atan; larger steps take
// the exact map.
glm::vec3 frame_rotation_vector(const glm::quat& q_in) {
  const glm::quat q = q_in.w < 0.0f ? -q_in : q_in;
  const float s2 = q.x * q.x + q.y * q.y + q.z * q.z;
  if (s2 < 0.01f) return glm::vec3(q.x, q.y, q.z) * (2.0f / q.w);
  return quat_to_rotation_vector(q);
}

// Local angular velocities (rad/s) and joint velocities (m/s) of the stored
// animation at `frame`; only translated joints get a velocity.
void pose_velocity(const Database& database, const AnimationData& animation, std::uint32_t frame,
                   std::span<glm::vec3> angular, std::span<glm::vec3> velocities) {
  const auto [a, b] = difference_frames(database, frame);
  const std::size_t joints = animation.joint_count();
  const float fps = database.fps();
  const glm::quat* qa = animation.local_rotations.data() + std::size_t{a} * joints;
  const glm::quat* qb = animation.local_rotations.data() + std::size_t{b} * joints;
  for (std::size_t j = 0; j < joints; ++j) {
    angular[j] = a == b ? glm::vec3(0.0f) : frame_rotation_vector(qb[j] * glm::inverse(qa[j])) * fps;
    velocities[j] = glm::vec3(0.0f);
  }
  const std::size_t count = animation.translated_joints.size();
  if (a == b) return;
  for (std::size_t t = 0; t < count; ++t) {
    velocities[animation.translated_joints[t]] =
        (animation.local_translations[std::size_t{b} * count + t] - animation.local_translations[std::size_t{a} * count + t]) *
        fps;
  }
}

}  // namespace

void CrowdController::play(std::uint32_t b, float dt, const CrowdInput& input, float correction) {
  const Database& database = *database_;
  const AnimationData& animation = *animation_;
  const auto flags = database.frame_flags();
  searched_[b] = 0;
  // 1. simulate.
  desired_velocity_[b] = input.desired_velocity[b];
  desired_yaw_[b] = input.desired_yaw.empty() ? yaw_of_velocity(desired_velocity_[b], desired_yaw_[b])
                                              : wrap_angle(input.desired_yaw[b]);
  simulate_step(sim_[b], desired_velocity_[b], desired_yaw_[b], params_.spring, dt);

  // 2. play on by dt along the clip.
  const std::uint32_t previous_flags = flags[nearest_frame(database, {frames_[b], fractions_[b]})];
  const PlaybackStep step = advance_playback(database, {frames_[b], fractions_[b]}, dt * database.fps());
  frames_[b] = step.time.frame;
  fractions_[b] = step.time.fraction;
  held_[b] = step.reached_end ? 1 : 0;
  // The root motion of the frame interval now played (the source velocity
  // of a jump).
  const RootDelta velocity = root_velocity_at(database, frames_[b]);
  played_velocity_[b] = velocity.translation;
  played_yaw_rate_[b] = velocity.yaw;

  // The pose at the new time plus the decaying offsets.
  const std::size_t base = std::size_t{b} * joints_;
  const std::span<glm::quat> rotations(anim_rotations_.data() + base, joints_);
  const std::span<glm::vec3> translations(anim_translations_.data() + base, joints_);
  sample_pose_at(animation, frames_[b], next_frame(database, frames_[b]), fractions_[b], rotations, translations);
  const Inertializer::RootOffset offset =
      inertializer_.update(b, params_.inertialization_half_life, dt, rotations, translations);
  const float yaw_before = root_yaw_[b];
  root_pos_[b] += yaw_rotate(step.root_translation + offset.velocity * dt, root_yaw_[b]);
  root_pos_[b].y = 0.0f;
  root_yaw_[b] = wrap_angle(root_yaw_[b] + step.root_yaw + offset.yaw_rate * dt);
  correct_root(b, dt, correction);
  yaw_rate_[b] = wrap_angle(root_yaw_[b] - yaw_before) / dt;
  history_.record(b, dt, root_pos_[b], root_yaw_[b]);
  const std::uint32_t nearest = nearest_frame(database, step.time);
  contacts_[b] = animation.contacts[nearest];
  measure_shown(b, dt, fresh_[b] != 0);
  display(b, dt);

  // 3. decide.
  search_timer_[b] -= dt;
  bool regular = false;
  if (search_timer_[b] <= 0.0f) {
    regular = true;
    search_timer_[b] = std::max(search_timer_[b] + params_.search_interval, 0.0f);
  }
  const std::uint32_t frame_flags = flags[nearest];
  const bool forced =
      force_[b] != 0 || step.reached_end || (frame_flags & kFrameDoNotUse) != 0 ||
      ((frame_flags & kFrameBlockTransition) != 0 && (previous_flags & kFrameBlockTransition) == 0) ||
      glm::length(desired_velocity_[b] - searched_velocity_[b]) > params_.force_search_velocity_change ||
      std::abs(wrap_angle(desired_yaw_[b] - searched_yaw_[b])) > params_.force_search_yaw_change;
  // A forced search leaves the regular schedule alone: resetting the timer
  // would bunch characters forced together (all of them on the first tick)
  // onto the same later ticks.
  due_flag_[b] = forced ? 2 : regular ? 1 : 0;
  force_[b] = 0;
}

void CrowdController::correct_root(std::uint32_t b, float dt, float correction) {
  glm::vec3 gap = sim_[b].position - root_pos_[b];
  gap.y = 0.0f;
  glm::vec3 step = gap * correction;
  const float step_length = glm::length(step);
  const float max_step = params_.max_correction_speed * dt;
  if (step_length > max_step) step *= max_step / step_length;
  root_pos_[b] += step;
  gap = sim_[b].position - root_pos_[b];
  gap.y = 0.0f;
  const float distance = glm::length(gap);
  if (distance > params_.max_correction_distance) {
    root_pos_[b] += gap * (1.0f - params_.max_correction_distance / distance);
  }
  float yaw_gap = wrap_angle(sim_[b].yaw - root_yaw_[b]);
  const float yaw_step = std::clamp(yaw_gap * correction, -params_.max_correction_yaw_rate * dt,
                                    params_.max_correction_yaw_rate * dt);
  root_yaw_[b] = wrap_angle(root_yaw_[b] + yaw_step);
  yaw_gap = wrap_angle(sim_[b].yaw - root_yaw_[b]);
  if (std::abs(yaw_gap) > params_.max_correction_yaw) {
    root_yaw_[b] = wrap_angle(sim_[b].yaw - std::copysign(params_.max_correction_yaw, yaw_gap));
  }
}

void CrowdController::measure_shown(std::uint32_t b, float dt, bool fresh) {
  const std::size_t base = std::size_t{b} * joints_;
  const glm::vec3 origin(0.0f);
  const float no_yaw = 0.0f;
  forward_kinematics_batch(animation_->skeleton, std::span(anim_rotations_).subspan(base, joints_),
                           std::span(anim_translations_).subspan(base, joints_), {&origin, 1}, {&no_yaw, 1},
                           std::span(joint_positions_).subspan(base, joints_));
  // Velocities by backward differences of world positions: what the viewer
  // sees, root motion and corrections included.
  const std::span<const int> joints = assembler_.velocity_joints();
  // One sine and cosine per character (yaw_rotate's, written out).
  const float c = std::cos(root_yaw_[b]);
  const float s = std::sin(root_yaw_[b]);
  for (std::size_t k = 0; k < joints.size(); ++k) {
    const glm::vec3 local = joint_positions_[base + static_cast<std::size_t>(joints[k])];
    const glm::vec3 world = root_pos_[b] + glm::vec3(local.x * c + local.z * s, local.y, -local.x * s + local.z * c);
    glm::vec3& last = velocity_world_[b * joints.size() + k];
    const glm::vec3 v = fresh || !(dt > 0.0f) ? glm::vec3(0.0f) : (world - last) / dt;
    joint_velocities_[b * joints.size() + k] = {v.x * c - v.z * s, v.y, v.x * s + v.z * c};
    last = world;
  }
  fresh_[b] = fresh && !(dt > 0.0f) ? 1 : 0;
}

void CrowdController::display(std::uint32_t b, float dt) {
  const std::size_t base = std::size_t{b} * joints_;
  const auto at = [base](auto& v) { return v.begin() + std::ptrdiff_t(base); };
  std::copy_n(at(anim_rotations_), joints_, at(rotations_));
  std::copy_n(at(anim_translations_), joints_, at(translations_));
  const std::span<glm::quat> rotations(rotations_.data() + base, joints_);
  const std::span<glm::vec3> translations(translations_.data() + base, joints_);
  const std::span<glm::vec3> world(world_.data() + base, joints_);
  const std::span<glm::vec3> animated(anim_world_.data() + base, joints_);
  if (locker_) {
    locker_->update(b, dt, contacts_[b], root_pos_[b], root_yaw_[b], rotations, translations, world, animated);
  } else {
    forward_kinematics_batch(animation_->skeleton, rotations, translations, {&root_pos_[b], 1}, {&root_yaw_[b], 1},
                             world);
    std::copy(world.begin(), world.end(), animated.begin());
  }
}

std::span<const std::uint8_t> CrowdController::foot_locked() const {
  return locker_ ? locker_->locked() : std::span<const std::uint8_t>(no_feet_flags_);
}

std::span<const glm::vec3> CrowdController::foot_anchors() const {
  return locker_ ? locker_->anchors() : std::span<const glm::vec3>(no_feet_anchors_);
}

std::span<const std::uint8_t> CrowdController::ik_reach_clamped() const {
  return locker_ ? locker_->reach_clamped() : std::span<const std::uint8_t>(no_feet_flags_);
}

void CrowdController::begin(float dt, const CrowdInput& input, ThreadPool& pool) {
  const float correction = 1.0f - std::exp2(-dt / params_.correction_half_life);
  for_characters(pool, characters_, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t i = begin; i < end; ++i) play(static_cast<std::uint32_t>(i), dt, input, correction);
  });
  // Compaction in character order: the batch order is deterministic.
  due_count_ = 0;
  last_.forced = 0;
  for (std::uint32_t b = 0; b < characters_; ++b) {
    if (due_flag_[b] == 0) continue;
    last_.forced += due_flag_[b] == 2 ? 1 : 0;
    due_[due_count_++] = b;
  }
  last_.searches = due_count_;
}

void CrowdController::assemble(ThreadPool& pool) {
  const std::uint32_t dims = database_->dims();
  const std::span<const float> offsets = assembler_.trajectory_offsets();
  const std::span<const float> past = assembler_.past_offsets();
  const std::size_t velocity_joints = assembler_.velocity_joints().size();
  const std::size_t t = trajectory_size_;
  for_characters(pool, due_count_, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t b = due_[i];
      const std::span<glm::vec3> positions(pred_pos_.data() + b * t, t);
      const std::span<float> yaws(pred_yaw_.data() + b * t, t);
      predict_trajectory(sim_[b], desired_velocity_[b], desired_yaw_[b], params_.spring, offsets, positions, yaws);
      searched_velocity_[b] = desired_velocity_[b];
      searched_yaw_[b] = desired_yaw_[b];
      searched_[b] = due_flag_[b];  // 1 regular, 2 forced
      due_refs_[i] = QueryFrame{root_pos_[b], root_yaw_[b]};
      const std::uint32_t nearest = nearest_frame(*database_, {frames_[b], fractions_[b]});
      const std::span<float> query = std::span(queries_).subspan(i * dims, dims);
      const std::span<glm::vec3> past_positions(past_pos_.data() + i * past.size(), past.size());
      const std::span<float> past_yaws(past_yaw_.data() + i * past.size(), past.size());
      for (std::size_t k = 0; k < past.size(); ++k) history_.at(b, past[k], past_positions[k], past_yaws[k]);
      ShownPose pose;
      pose.frame = nearest;
      pose.joint_positions = std::span<const glm::vec3>(joint_positions_).subspan(std::size_t{b} * joints_, joints_);
      pose.joint_velocities =
          std::span<const glm::vec3>(joint_velocities_).subspan(b * velocity_joints, velocity_joints);
      pose.yaw_rate = yaw_rate_[b];
      pose.contacts = contacts_[b];
      pose.past_positions = past_positions;
      pose.past_yaws = past_yaws;
      assembler_.assemble_shown(pose, due_refs_[i], positions, yaws, query);
      QueryParams& p = batch_params_[i];
      p = query_params_[b];
      // A character held on a non-looping clip's last frame has nothing to
      // play on: that frame gets no continuing bonus, else it wins the
      // forced search it triggers and the character searches every tick.
      p.continuing_frame = held_[b] != 0 ? kNoFrame : nearest;
      p.continuing_bias = params_.continuing_bias;
      p.continuing_multiplier = params_.continuing_multiplier;
      p.exclusion_window = params_.exclusion_window;
      continuing_[i] = nearest;
    }
  });
}

bool CrowdController::same_location(std::uint32_t b, std::uint32_t to) const {
  const auto frame_clip = database_->frame_clip();
  const std::uint32_t frame = frames_[b];
  if (frame_clip[to] != frame_clip[frame]) return false;
  const Clip& clip = database_->clips()[frame_clip[frame]];
  // Frames from the character's time to the match, the shorter way round a loop.
  float distance = float(to) - (float(frame) + fractions_[b]);
  if (clip.loop) {
    const auto length = float(clip.frame_count);
    distance = std::remainder(distance, length);
  }
  return std::abs(distance) <= params_.same_location_window * database_->fps();
}

void CrowdController::jump(std::uint32_t b, std::uint32_t to, unsigned thread) {
  const Database& database = *database_;
  const AnimationData& animation = *animation_;
  JumpScratch& s = scratch_[thread];
  const std::span<glm::quat> rotations(anim_rotations_.data() + std::size_t{b} * joints_, joints_);
  const std::span<glm::vec3> translations(anim_translations_.data() + std::size_t{b} * joints_, joints_);
  // Source: what the character shows now (played pose + offsets), moving at
  // the played velocities plus the offsets' own rates.
  pose_velocity(database, animation, frames_[b], s.source_angular, s.source_velocities);
  const std::span<const glm::vec3> rotation_rates = inertializer_.rotation_offset_velocities(b);
  for (std::size_t j = 0; j < joints_; ++j) s.source_angular[j] += rotation_rates[j];
  const std::span<const glm::vec3> translation_rates = inertializer_.translation_offset_velocities(b);
  for (std::size_t t = 0; t < translation_rates.size(); ++t) {
    s.source_velocities[animation.translated_joints[t]] += translation_rates[t];
  }
  const Inertializer::RootOffset root = inertializer_.root_offset(b);
  Inertializer::PoseState source{rotations, s.source_angular, translations, s.source_velocities,
                                 played_velocity_[b] + root.velocity, played_yaw_rate_[b] + root.yaw_rate};
  sample_pose(animation, to, s.rotations, s.translations);
  pose_velocity(database, animation, to, s.angular, s.velocities);
  const RootDelta to_root = root_velocity_at(database, to);
  Inertializer::PoseState destination{s.rotations, s.angular, s.translations, s.velocities, to_root.translation,
                                      to_root.yaw};
  inertializer_.transition(b, source, destination);
  // The output this tick: the destination under the full offset, which is
  // the source pose (continuity at the jump).
  std::copy(s.rotations.begin(), s.rotations.end(), rotations.begin());
  std::copy(s.translations.begin(), s.translations.end(), translations.begin());
  (void)inertializer_.update(b, params_.inertialization_half_life, 0.0f, rotations, translations);
  played_velocity_[b] = to_root.translation;
  played_yaw_rate_[b] = to_root.yaw;
  frames_[b] = to;
  fractions_[b] = 0.0f;
  held_[b] = 0;
  jumped_[b] = 1;
}

void CrowdController::apply(std::span<const Match> matches, std::span<const std::uint32_t> characters,
                            std::span<const std::uint32_t> continuing, ThreadPool& pool) {
  ensure_scratch(pool.thread_count());
  for_characters(pool, characters.size(), [&](std::size_t begin, std::size_t end, unsigned thread) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t b = characters[i];
      const Match& m = matches[i];
      match_cost_[b] = m.cost;
      if (m.frame == kNoFrame || m.frame == continuing[i]) continue;
      if (same_location(b, m.frame)) {
        suppressed_[b] = 1;
        continue;
      }
      jump(b, m.frame, thread);
    }
  });
  last_.applied = static_cast<std::uint32_t>(characters.size());
  last_.jumps = 0;
  last_.same_location = 0;
  last_.no_candidate = 0;
  for (std::size_t i = 0; i < characters.size(); ++i) {
    last_.jumps += jumped_[characters[i]];
    last_.same_location += suppressed_[characters[i]];
    last_.no_candidate += matches[i].frame == kNoFrame ? 1 : 0;
  }
}

namespace {

void add_totals(TickStats& totals, const TickStats& tick) {
  totals.searches += tick.searches;
  totals.forced += tick.forced;
  totals.batches += tick.batches;
  totals.applied += tick.applied;
  totals.jumps += tick.jumps;
  totals.same_location += tick.same_location;
  totals.no_candidate += tick.no_candidate;
}

}  // namespace

QueryBatch CrowdController::due_batch() const {
  QueryBatch batch;
  batch.features = std::span<const float>(queries_).first(std::size_t{due_count_} * database_->dims());
  batch.params = std::span<const QueryParams>(batch_params_).first(due_count_);
  batch.size = due_count_;
  return batch;
}

Status CrowdController::tick(float dt, const CrowdInput& input, SearchBackend& backend, ThreadPool& pool) {
  MMVK_TRY(check_input(dt, input));
  if (&backend.database() != database_) return make_error("crowd controller: the backend searches another database");
  last_ = TickStats{};
  std::fill(jumped_.begin(), jumped_.end(), std::uint8_t{0});
  std::fill(suppressed_.begin(), suppressed_.end(), std::uint8_t{0});
  begin(dt, input, pool);
  assemble(pool);
  if (due_count_ > 0) {
    Status status = backend.search(due_batch(), 1, std::span(matches_).first(due_count_));
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    ++last_.batches;
  }
  apply(std::span<const Match>(matches_).first(due_count_), std::span<const std::uint32_t>(due_).first(due_count_),
        std::span<const std::uint32_t>(continuing_).first(due_count_), pool);
  add_totals(totals_, last_);
  ++ticks_;
  return {};
}

Status CrowdController::tick(float dt, const CrowdInput& input, AsyncSearch& search, ThreadPool& pool) {
  MMVK_TRY(check_input(dt, input));
  if (&search.database() != database_) return make_error("crowd controller: the search runs on another database");
  last_ = TickStats{};
  // The previous tick's results first, as if they had arrived at its end.
  std::fill(jumped_.begin(), jumped_.end(), std::uint8_t{0});
  std::fill(suppressed_.begin(), suppressed_.end(), std::uint8_t{0});
  TickStats applied;
  if (pending_count_ > 0) {
    Status status = search.collect(std::span(matches_).first(pending_count_));
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    apply(std::span<const Match>(matches_).first(pending_count_),
          std::span<const std::uint32_t>(pending_).first(pending_count_),
          std::span<const std::uint32_t>(pending_continuing_).first(pending_count_), pool);
    applied = last_;
    pending_count_ = 0;
  }
  begin(dt, input, pool);
  last_.applied = applied.applied;
  last_.jumps = applied.jumps;
  last_.same_location = applied.same_location;
  last_.no_candidate = applied.no_candidate;
  assemble(pool);
  if (due_count_ > 0) {
    Status status = search.submit(due_batch());
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    ++last_.batches;
    std::copy_n(due_.begin(), due_count_, pending_.begin());
    std::copy_n(continuing_.begin(), due_count_, pending_continuing_.begin());
    pending_count_ = due_count_;
  }
  add_totals(totals_, last_);
  ++ticks_;
  return {};
}

void CrowdController::world_positions(std::span<glm::vec3> out, ThreadPool&) const {
  // Written by display() each tick (the locker computes them anyway).
  std::copy(world_.begin(), world_.end(), out.begin());
}

void CrowdController::animated_world_positions(std::span<glm::vec3> out, ThreadPool& pool) const {
  forward_kinematics_batch(animation_->skeleton, anim_rotations_, anim_translations_, root_pos_, root_yaw_, out,
                           &pool);
}

}  // namespace mmvk
