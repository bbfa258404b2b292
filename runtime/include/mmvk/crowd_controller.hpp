// CrowdController: motion matching for B characters at once. It owns every
// character's state in arrays (playback frame, search timer, spring
// simulation, inertialization offsets, animated root) and runs the standard
// controller loop once per tick, batched: one search per tick for all the
// characters that are due. docs/animation.md describes the loop in prose.
//
// One tick (dt seconds), synchronous form tick(dt, input, backend, pool):
//   1. simulate: each simulated root moves toward its desired velocity and
//      facing (critically damped springs, trajectory.hpp);
//   2. play: each character's continuous time in its clip advances by
//      dt * fps frames (playback.hpp: a looping clip wraps to its first
//      frame; a non-looping clip holds its last frame); its pose is
//      interpolated between the two neighbouring frames, plus the decaying
//      inertialization offsets; its animated root moves along the clip's root
//      path plus the inertialization's root offset, then is corrected toward
//      the simulated root (step 7); its root path is recorded (RootHistory);
//   3. decide: a character is due when its search timer runs out (timers
//      are staggered over the interval so the load per tick is flat), or a
//      search is forced: first tick, the end of a non-looping clip, a
//      do_not_use frame, entering a block_transition range, or a desired
//      velocity or facing that changed sharply since its last search;
//   4. assemble: one normalized query per due character into a [due x dims]
//      batch (query_assembly.hpp): pose channels measured on the pose it
//      shows (after blending, before foot IK), past trajectory from its
//      recorded root path, future trajectory from its prediction;
//   5. search: the batch on the backend, in one call (every backend takes
//      any batch up to kMaxBatch);
//   6. apply: a character jumps only when its match is neither the
//      continuing frame (the frame nearest its time) nor within
//      same_location_window of its time in the same clip; a jump plays on
//      from the matched frame and starts an inertialization (pose_batch.hpp);
//   7. correct: the animated root is pulled toward the simulated root with a
//      bounded correction (ControllerParams); then foot locking holds planted
//      feet on the ground through two-bone IK (foot_locker.hpp): the
//      displayed pose.
// Deferred form tick(dt, input, async, pool): steps 5-6 split: the batch is
// submitted in step 5 and its results are applied at the start of the next
// tick (one tick of latency), so a GPU search overlaps the caller's work.
//
// No global state, no threads of its own (it uses the caller's ThreadPool),
// no allocation per tick. Not thread-safe. The Database must outlive it.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "mmvk/animation_data.hpp"
#include "mmvk/async_search.hpp"
#include "mmvk/database.hpp"
#include "mmvk/foot_locker.hpp"
#include "mmvk/pose_batch.hpp"
#include "mmvk/query_assembly.hpp"
#include "mmvk/root_history.hpp"
#include "mmvk/search.hpp"
#include "mmvk/status.hpp"
#include "mmvk/thread_pool.hpp"
#include "mmvk/trajectory.hpp"

namespace mmvk {

struct ControllerParams {
  float search_interval = 0.1f;            // seconds between a character's regular searches
  float inertialization_half_life = 0.1f;  // seconds
  SpringParams spring;                     // simulated root (and prediction) half-lives
  // Forced search when the desired velocity changed by more than this since
  // the character's last search (m/s), or the desired yaw by more than
  // force_search_yaw_change (radians).
  float force_search_velocity_change = 1.0f;
  float force_search_yaw_change = 0.6f;
  // Root correction: each tick the animated root moves toward the simulated
  // one by the fraction 1 - 2^(-dt / correction_half_life) of the gap, at
  // most max_correction_speed * dt metres (and max_correction_yaw_rate * dt
  // radians); a gap still larger than max_correction_distance (or
  // max_correction_yaw) is then clamped to it, so a character never drifts
  // further than that from its simulated position.
  float correction_half_life = 0.2f;      // seconds
  float max_correction_speed = 1.0f;      // m/s
  float max_correction_distance = 0.5f;   // metres
  float max_correction_yaw_rate = 3.0f;   // rad/s
  float max_correction_yaw = 0.6f;        // radians
  // Search options applied to every query (per-character tags: query_params()).
  float continuing_bias = 0.0f;
  float continuing_multiplier = 1.0f;  // finite, >= 0 (QueryParams::continuing_multiplier)
  std::uint32_t exclusion_window = 0;
  // A match in the clip being played, within this many seconds of the
  // character's time (before or after), is not jumped to: playing on shows
  // the same motion without a blend (Motion Symphony's "same location"
  // rule). >= 0; 0 suppresses only the continuing frame.
  float same_location_window = 0.2f;
  // Foot locking: planted feet held where they touched down, legs solved by
  // two-bone IK on the displayed pose (foot_locker.hpp). Its bones are the
  // roles @hips, @left_/@right_upper_leg, _lower_leg, _foot and _toe;
  // enabled = false lets a skeleton without them through.
  FootIkParams foot_ik;
};

// Per-tick input, [B] each.
struct CrowdInput {
  std::span<const glm::vec3> desired_velocity;  // world m/s, y ignored
  // Desired facing yaw (radians), or empty: face the desired velocity (and
  // keep the current facing while it is below 1e-3 m/s).
  std::span<const float> desired_yaw;
};

struct TickStats {
  std::uint32_t searches = 0;      // queries assembled this tick
  std::uint32_t forced = 0;        // of which forced
  std::uint32_t batches = 0;       // backend calls (1 on a tick with searches)
  std::uint32_t applied = 0;       // results applied this tick
  std::uint32_t jumps = 0;         // results that were jumped to
  std::uint32_t same_location = 0; // results not jumped to: within same_location_window of the character's time
  std::uint32_t no_candidate = 0;  // results with no frame (kept playing)
};

class CrowdController {
 public:
  // Errors: the database has no animation (missing_animation_error), its
  // schema has no trajectory_position channel, characters == 0 or over kMaxBatch, parameters
  // out of range (each names the field).
  static Result<CrowdController> create(const Database& database, std::uint32_t characters,
                                        const ControllerParams& params = {});

  // Places character b (before or between ticks): root and simulated root at
  // `position` (y set to 0) facing `yaw`, playing database frame `frame`;
  // its next tick forces a search. Characters start at the origin, yaw 0,
  // frame 0. Errors: b or frame out of range.
  Status place(std::uint32_t b, const glm::vec3& position, float yaw, std::uint32_t frame = 0);

  // Synchronous tick: search and apply within the tick.
  Status tick(float dt, const CrowdInput& input, SearchBackend& backend, ThreadPool& pool);
  // Deferred tick: apply the previous tick's results, then submit this one's.
  Status tick(float dt, const CrowdInput& input, AsyncSearch& search, ThreadPool& pool);

  // World joint positions of every character into out [B x joints].
  void world_positions(std::span<glm::vec3> out, ThreadPool& pool) const;

  std::uint32_t size() const { return characters_; }
  const Database& database() const { return *database_; }
  const AnimationData& animation() const { return *animation_; }
  const ControllerParams& params() const { return params_; }
  const TickStats& last_tick() const { return last_; }
  const TickStats& totals() const { return totals_; }
  std::uint64_t ticks() const { return ticks_; }

  // Per-character query options (tags, weights); the controller overwrites
  // continuing_frame, continuing_bias, continuing_multiplier and exclusion_window.
  std::span<QueryParams> query_params() { return query_params_; }

  // Per-character output, [B] unless noted.
  std::span<const std::uint32_t> frames() const { return frames_; }          // database frame played
  std::span<const float> frame_fractions() const { return fractions_; }    // of the way to the next frame, [0, 1)
  std::span<const glm::vec3> root_positions() const { return root_pos_; }   // animated root, world, y = 0
  std::span<const float> root_yaws() const { return root_yaw_; }
  std::span<const SimulationState> simulation() const { return sim_; }      // simulated root
  // This tick's search of each character: 0 none, 1 a regular one (its
  // timer ran out), 2 a forced one (placement, a clip's end, a sharp change
  // of the desired velocity or yaw; ControllerParams' force_search_*).
  std::span<const std::uint8_t> searched() const { return searched_; }
  std::span<const std::uint8_t> jumped() const { return jumped_; }          // 1: jumped this tick
  std::span<const float> match_costs() const { return match_cost_; }        // last applied match (inf: none)
  std::span<const std::uint8_t> contacts() const { return contacts_; }      // FootContact bits of the nearest frame
  // The trajectory of each character's last search: [B x T] world positions
  // and yaws, T = trajectory_offsets().size().
  std::span<const float> trajectory_offsets() const { return assembler_.trajectory_offsets(); }
  std::span<const glm::vec3> predicted_positions() const { return pred_pos_; }
  std::span<const float> predicted_yaws() const { return pred_yaw_; }
  // The output pose, character space: [B x joints] each.
  std::span<const glm::quat> local_rotations() const { return rotations_; }
  std::span<const glm::vec3> local_translations() const { return translations_; }
  // The animated pose before foot IK (what queries measure), character
  // space, [B x joints] each, and its world joint positions into out.
  std::span<const glm::quat> animated_rotations() const { return anim_rotations_; }
  std::span<const glm::vec3> animated_translations() const { return anim_translations_; }
  void animated_world_positions(std::span<glm::vec3> out, ThreadPool& pool) const;
  // The same positions as the last display saw them, [B x joints], kept at no
  // cost (the foot locker's FK): after a tick that took the previous tick's
  // matches (the AsyncSearch tick) they equal animated_world_positions() bit
  // for bit; after the synchronous tick a character that jumped shows here
  // its pose before the jump.
  std::span<const glm::vec3> displayed_animated_world() const { return anim_world_; }
  // Foot locking (ControllerParams::foot_ik), per character and foot
  // (left, right), [B x 2]: 1 while the foot is held where it was planted;
  // the world position it is held at (metres); 1 when the leg could not
  // reach its target this tick and was soft-clamped. All 0 with foot IK off.
  std::span<const std::uint8_t> foot_locked() const;
  std::span<const glm::vec3> foot_anchors() const;
  std::span<const std::uint8_t> ik_reach_clamped() const;
  // The locker itself (hip drops, corrections), or null with foot IK off
  // on a skeleton without legs.
  const FootLocker* foot_locker() const { return locker_ ? &*locker_ : nullptr; }

 private:
  CrowdController() = default;
  Status check_input(float dt, const CrowdInput& input) const;
  // Steps 1-3 and the blend, for every character; fills due_.
  void begin(float dt, const CrowdInput& input, ThreadPool& pool);
  // Step 4 for due_.
  void assemble(ThreadPool& pool);
  // The assembled queries of due_ as one batch (views into the scratch).
  QueryBatch due_batch() const;
  // Step 6: matches [count] for characters[count] whose queries continued
  // continuing[count]; updates last_.
  void apply(std::span<const Match> matches, std::span<const std::uint32_t> characters,
             std::span<const std::uint32_t> continuing, ThreadPool& pool);
  // Steps 1-3 and the blend for character b.
  void play(std::uint32_t b, float dt, const CrowdInput& input, float correction);
  // The measurements of b's animated pose that queries read: its joint
  // positions, joint velocities and yaw rate; `fresh`: no previous tick.
  void measure_shown(std::uint32_t b, float dt, bool fresh);
  // b's displayed pose: the animated one with its feet locked (foot IK),
  // and its world joint positions.
  void display(std::uint32_t b, float dt);
  // Pulls b's animated root toward its simulated root (step 7).
  void correct_root(std::uint32_t b, float dt, float correction);
  // b's match `to` is close enough to its time to play on instead.
  bool same_location(std::uint32_t b, std::uint32_t to) const;
  void jump(std::uint32_t b, std::uint32_t to, unsigned thread);
  void ensure_scratch(unsigned threads);

  const Database* database_ = nullptr;
  const AnimationData* animation_ = nullptr;
  ControllerParams params_;
  QueryAssembler assembler_;
  Inertializer inertializer_;
  std::uint32_t characters_ = 0;
  std::uint32_t joints_ = 0;
  std::uint32_t trajectory_size_ = 0;
  std::uint64_t ticks_ = 0;
  TickStats last_, totals_;

  // Per character, [B].
  std::vector<std::uint32_t> frames_;
  std::vector<float> fractions_;         // of the way from frames_ to the next frame, [0, 1)
  std::vector<float> search_timer_;      // seconds to the next regular search
  std::vector<std::uint8_t> force_;      // forced search pending (placed, first tick)
  std::vector<std::uint8_t> due_flag_;   // 0 no search, 1 regular, 2 forced
  std::vector<std::uint8_t> searched_, jumped_, suppressed_, contacts_;
  std::vector<float> match_cost_;
  std::vector<glm::vec3> root_pos_;
  std::vector<float> root_yaw_;
  std::vector<float> yaw_rate_;             // the animated root's turning rate, rad/s
  RootHistory history_;
  std::vector<glm::vec3> played_velocity_;  // root velocity of the played frames, character space, m/s
  std::vector<float> played_yaw_rate_;      // rad/s
  std::vector<SimulationState> sim_;
  std::vector<glm::vec3> desired_velocity_, searched_velocity_;
  std::vector<float> desired_yaw_, searched_yaw_;
  std::vector<QueryParams> query_params_;
  std::vector<glm::vec3> pred_pos_;      // [B x T]
  std::vector<float> pred_yaw_;          // [B x T]
  std::vector<glm::quat> rotations_;     // [B x joints] displayed
  std::vector<glm::vec3> translations_;  // [B x joints] displayed
  std::vector<glm::quat> anim_rotations_;     // [B x joints] animated, before IK
  std::vector<glm::vec3> anim_translations_;  // [B x joints]
  std::vector<glm::vec3> joint_positions_;    // [B x joints] character space, of the animated pose
  std::vector<glm::vec3> velocity_world_;     // [B x V] world positions of the assembler's velocity joints
  std::vector<glm::vec3> joint_velocities_;   // [B x V] their velocities, character space
  std::vector<std::uint8_t> fresh_;           // [B] placed since the last tick: no velocities yet
  std::vector<std::uint8_t> held_;            // [B] on a non-looping clip's last frame
  std::optional<FootLocker> locker_;
  std::vector<glm::vec3> world_;              // [B x joints] displayed world joint positions
  std::vector<glm::vec3> anim_world_;         // [B x joints] the same before foot IK
  std::vector<std::uint8_t> no_feet_flags_;   // [B x 2] zeros, without a locker
  std::vector<glm::vec3> no_feet_anchors_;    // [B x 2]

  // The batch, [B] capacity.
  std::vector<std::uint32_t> due_;       // characters in the batch, ascending
  std::vector<std::uint32_t> continuing_;  // their continuing frames
  std::vector<QueryFrame> due_refs_;
  std::vector<float> queries_;           // [B x dims]
  std::vector<glm::vec3> past_pos_;      // [B x past offsets] of the batch
  std::vector<float> past_yaw_;
  std::vector<QueryParams> batch_params_;
  std::vector<Match> matches_;
  std::uint32_t due_count_ = 0;
  // Deferred: the batch in flight (copies of due_ and continuing_).
  std::vector<std::uint32_t> pending_, pending_continuing_;
  std::uint32_t pending_count_ = 0;
  // Per pool thread: a destination pose and velocities for jumps.
  struct JumpScratch {
    std::vector<glm::quat> rotations;
    std::vector<glm::vec3> translations, angular, velocities, source_angular, source_velocities;
  };
  std::vector<JumpScratch> scratch_;
};

}  // namespace mmvk
