// The batched motion matching controller loop (crowd_controller.hpp): the
// state's setup, placement and the two ticks. The passes of a tick are in
// crowd_controller_passes.cpp.
#include "mmvk/animation/crowd_controller.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>
#include <string>

#include "mmvk/animation/spring.hpp"
#include "play_rate.hpp"

namespace mmvk {

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Fractions of stagger: the golden ratio spreads any number of characters
// evenly over the interval, whatever the tick rate.
constexpr float kGolden = 0.6180339887f;

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
  if (!std::isfinite(params.correction_dead_zone) || params.correction_dead_zone < 0.0f ||
      !(params.correction_dead_zone < params.max_correction_distance)) {
    return make_error("crowd controller: correction_dead_zone must be finite, >= 0 and below "
                      "max_correction_distance (metres), got " + std::to_string(params.correction_dead_zone));
  }
  return detail::check_speed_params(params);
}


}  // namespace

void CrowdController::size_state(std::uint32_t characters) {
  const std::size_t n = characters;
  const std::size_t poses = n * joints_;
  playback_.frames.assign(n, 0);
  playback_.fractions.assign(n, 0.0f);
  playback_.held.assign(n, 0);
  playback_.contacts.assign(n, animation_->contacts[0]);
  playback_.played_velocity.assign(n, glm::vec3(0.0f));
  playback_.played_yaw_rate.assign(n, 0.0f);
  playback_.rate.assign(n, 1.0f);
  playback_.stride.assign(n, 1.0f);
  playback_.step_translation.assign(n, glm::vec3(0.0f));
  playback_.step_yaw.assign(n, 0.0f);
  roots_.position.assign(n, glm::vec3(0.0f));
  roots_.yaw.assign(n, 0.0f);
  roots_.start_yaw.assign(n, 0.0f);
  roots_.yaw_rate.assign(n, 0.0f);
  roots_.animated_speed.assign(n, 0.0f);
  roots_.correction.assign(n, glm::vec3(0.0f));
  roots_.simulated.assign(n, SimulationState{});
  const std::span<const float> past = assembler_.past_offsets();
  roots_.history = RootHistory(characters, past.empty() ? 0.0f : *std::max_element(past.begin(), past.end()));
  schedule_.timer.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    const float fraction = static_cast<float>(b) * kGolden;
    schedule_.timer[b] = params_.search_interval * (fraction - std::floor(fraction));
  }
  schedule_.force.assign(n, 1);
  schedule_.was_blocked.assign(n, 0);
  schedule_.due.assign(n, SearchKind::None);
  schedule_.searched.assign(n, SearchKind::None);
  schedule_.desired_velocity.assign(n, glm::vec3(0.0f));
  schedule_.searched_velocity.assign(n, glm::vec3(0.0f));
  schedule_.desired_yaw.assign(n, 0.0f);
  schedule_.searched_yaw.assign(n, 0.0f);
  schedule_.query_params.assign(n, QueryParams{});
  schedule_.predicted_positions.assign(n * trajectory_size_, glm::vec3(0.0f));
  schedule_.predicted_yaws.assign(n * trajectory_size_, 0.0f);
  gaits_.state.assign(n, GaitState{});
  gaits_.constraint.assign(n, GaitConstraint{});
  gaits_.own_require.assign(n, 0);
  gaits_.own_exclude.assign(n, 0);
  gaits_.own_gait.assign(n, 0);
  gaits_.first.assign(n, 1);
  gaits_.holding.assign(n, 0);
  gaits_.entry.assign(n, 0);
  outcome_.jumped.assign(n, 0);
  outcome_.suppressed.assign(n, 0);
  outcome_.match_cost.assign(n, std::numeric_limits<float>::infinity());
  for (auto* v : {&poses_.animated_translations, &poses_.animated_world, &poses_.translations, &poses_.world}) {
    v->resize(poses);
  }
  poses_.animated_rotations.resize(poses);
  poses_.rotations.resize(poses);
  const std::size_t velocity_joints = assembler_.velocity_joints().size();
  poses_.velocity_world.assign(n * velocity_joints, glm::vec3(0.0f));
  poses_.joint_velocities.assign(n * velocity_joints, glm::vec3(0.0f));
  poses_.fresh.assign(n, 1);
  no_feet_flags_.assign(2 * n, 0);
  no_feet_vectors_.assign(2 * n, glm::vec3(0.0f));
  for (auto* v : {&batch_.characters, &batch_.continuing, &in_flight_.characters, &in_flight_.continuing,
                  &applied_.characters}) {
    v->resize(n);
  }
  batch_.frames.resize(n);
  batch_.queries.resize(n * database_->dims());
  batch_.past_positions.resize(n * past.size());
  batch_.past_yaws.resize(n * past.size());
  batch_.params.resize(n);
  applied_.matches.resize(n);
}

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
  c.stride_speeds_ = detail::stride_speeds(database, params.stride_window);
  c.size_state(characters);
  c.start_gaits();
  if (locker.ok()) c.locker_ = std::move(*locker);
  for (std::uint32_t b = 0; b < characters; ++b) MMVK_TRY(c.place(b, glm::vec3(0.0f), 0.0f, 0));
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
  const float facing = wrap_angle(yaw);
  roots_.position[b] = ground;
  roots_.yaw[b] = facing;
  roots_.yaw_rate[b] = 0.0f;
  roots_.correction[b] = glm::vec3(0.0f);
  roots_.simulated[b] = SimulationState{};
  roots_.simulated[b].position = ground;
  roots_.simulated[b].yaw = facing;
  roots_.history.reset(b, ground, facing);
  schedule_.desired_velocity[b] = schedule_.searched_velocity[b] = glm::vec3(0.0f);
  schedule_.desired_yaw[b] = schedule_.searched_yaw[b] = facing;
  schedule_.force[b] = 1;
  playback_.frames[b] = frame;
  playback_.fractions[b] = 0.0f;
  playback_.held[b] = 0;
  playback_.played_velocity[b] = glm::vec3(0.0f);
  playback_.played_yaw_rate[b] = 0.0f;
  playback_.rate[b] = playback_.stride[b] = 1.0f;
  playback_.contacts[b] = animation_->contacts[frame];
  gaits_.first[b] = 1;
  gaits_.holding[b] = 0;
  inertializer_.reset(b);
  const std::size_t base = std::size_t{b} * joints_;
  sample_pose(*animation_, frame, std::span(poses_.animated_rotations).subspan(base, joints_),
              std::span(poses_.animated_translations).subspan(base, joints_));
  measure(b, 0.0f, true);
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
  for (ThreadScratch& s : scratch_) {
    s.rotations.resize(joints_);
    for (auto* v : {&s.translations, &s.angular, &s.velocities, &s.source_angular, &s.source_velocities,
                    &s.joint_positions}) {
      v->resize(joints_);
    }
  }
}

std::span<const std::uint8_t> CrowdController::foot_locked() const {
  return locker_ ? locker_->locked() : std::span<const std::uint8_t>(no_feet_flags_);
}

std::span<const glm::vec3> CrowdController::foot_anchors() const {
  return locker_ ? locker_->anchors() : std::span<const glm::vec3>(no_feet_vectors_);
}

std::span<const glm::vec3> CrowdController::foot_corrections() const {
  return locker_ ? locker_->corrections() : std::span<const glm::vec3>(no_feet_vectors_);
}

std::span<const std::uint8_t> CrowdController::ik_reach_clamped() const {
  return locker_ ? locker_->reach_clamped() : std::span<const std::uint8_t>(no_feet_flags_);
}

void CrowdController::start_tick(ThreadPool& pool) {
  ensure_scratch(pool.thread_count());
  last_ = TickStats{};
  std::fill(outcome_.jumped.begin(), outcome_.jumped.end(), std::uint8_t{0});
  std::fill(outcome_.suppressed.begin(), outcome_.suppressed.end(), std::uint8_t{0});
  applied_.count = 0;
}

void CrowdController::finish_tick() {
  totals_.searches += last_.searches;
  totals_.forced += last_.forced;
  totals_.batches += last_.batches;
  totals_.applied += last_.applied;
  totals_.jumps += last_.jumps;
  totals_.same_location += last_.same_location;
  totals_.no_candidate += last_.no_candidate;
  totals_.search_seconds += last_.search_seconds;
  ++ticks_;
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

QueryBatch CrowdController::batch_queries() const {
  QueryBatch batch;
  batch.features = std::span<const float>(batch_.queries).first(std::size_t{batch_.count} * database_->dims());
  batch.params = std::span<const QueryParams>(batch_.params).first(batch_.count);
  batch.size = batch_.count;
  return batch;
}

Status CrowdController::tick(float dt, const CrowdInput& input, SearchBackend& backend, ThreadPool& pool) {
  MMVK_TRY(check_input(dt, input));
  if (&backend.database() != database_) return make_error("crowd controller: the backend searches another database");
  start_tick(pool);
  advance(dt, input, pool);  // 1-4
  assemble(pool);            // 5
  const std::uint32_t count = batch_.count;
  if (count > 0) {  // 6
    const Clock::time_point start = Clock::now();
    Status status = backend.search(batch_queries(), 1, std::span(applied_.matches).first(count));
    last_.search_seconds += seconds_since(start);
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    ++last_.batches;
  }
  std::copy_n(batch_.characters.begin(), count, applied_.characters.begin());
  applied_.count = count;
  apply(std::span<const std::uint32_t>(batch_.continuing).first(count), pool);  // 7
  display(dt, true, pool);                                                     // 8
  finish_tick();
  return {};
}

Status CrowdController::tick(float dt, const CrowdInput& input, AsyncSearch& search, ThreadPool& pool) {
  MMVK_TRY(check_input(dt, input));
  if (&search.database() != database_) return make_error("crowd controller: the search runs on another database");
  start_tick(pool);
  // 7 of the previous tick first, as if its results had arrived at its end.
  const std::uint32_t pending = in_flight_.count;
  if (pending > 0) {
    const Clock::time_point start = Clock::now();
    Status status = search.collect(std::span(applied_.matches).first(pending));
    last_.search_seconds += seconds_since(start);
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    std::copy_n(in_flight_.characters.begin(), pending, applied_.characters.begin());
    applied_.count = pending;
    apply(std::span<const std::uint32_t>(in_flight_.continuing).first(pending), pool);
    in_flight_.count = 0;
  }
  advance(dt, input, pool);  // 1-4
  assemble(pool);            // 5
  const std::uint32_t count = batch_.count;
  if (count > 0) {  // 6, submitted
    const Clock::time_point start = Clock::now();
    Status status = search.submit(batch_queries());
    last_.search_seconds += seconds_since(start);
    if (!status.ok()) return make_error("crowd controller: search: " + status.message());
    ++last_.batches;
    std::copy_n(batch_.characters.begin(), count, in_flight_.characters.begin());
    std::copy_n(batch_.continuing.begin(), count, in_flight_.continuing.begin());
    in_flight_.count = count;
  }
  display(dt, false, pool);  // 8
  finish_tick();
  return {};
}

}  // namespace mmvk
