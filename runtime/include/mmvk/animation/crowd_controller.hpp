// CrowdController: motion matching for B characters at once. It owns every
// character's state in arrays, grouped by stage (playback, roots, search
// schedule, poses, the batch), and runs the standard controller loop once per
// tick as one pass per stage over all characters: one search per tick for
// all the characters that are due. docs/animation.md describes the loop in
// prose, with the same numbers.
//
// One tick (dt seconds), synchronous form tick(dt, input, backend, pool):
//   1. simulate and play: each simulated root moves toward its desired
//      velocity and facing (critically damped springs, trajectory.hpp); each
//      character's continuous time in its clip advances by dt * fps * its
//      play rate frames, the rate and the stride scale of its root motion
//      chosen so that the animation moves at the simulated root's speed
//      (within ControllerParams' bounds; playback.hpp: a looping clip wraps
//      to its first frame; a non-looping clip holds its last frame);
//   2. blend: its pose is interpolated between the two neighbouring frames,
//      plus the decaying inertialization offsets (pose_batch.hpp), and its
//      animated root moves along the clip's root path plus the
//      inertialization's root offset;
//   3. correct: the animated root is pulled toward the simulated root with a
//      bounded correction (ControllerParams; at most a fraction of the
//      animated root's own speed, so it removes drift); its path is recorded
//      (RootHistory), and the animated pose is measured: one forward
//      kinematics in the world per character, from which the queries' joint
//      positions (character space) and velocities come and which the foot
//      locker reads;
//   4. decide: a character is due when its search timer runs out (timers
//      are staggered over the interval so the load per tick is flat), or a
//      search is forced: first tick, the end of a non-looping clip, a
//      do_not_use frame, entering a block_transition range, or a desired
//      velocity or facing that changed sharply since its last search;
//   5. assemble: its trajectory is predicted and one normalized query per
//      due character goes into a [due x dims] batch (query_assembly.hpp):
//      pose channels measured on the animated pose (after blending, before
//      foot IK), past trajectory from its recorded root path, future
//      trajectory from its prediction;
//   6. search: the batch on the backend, in one call (every backend takes
//      any batch up to kMaxBatch);
//   7. apply: a character jumps only when its match is neither the
//      continuing frame (the frame nearest its time) nor within
//      same_location_window of its time in the same clip; a jump plays on
//      from the matched frame and starts an inertialization (pose_batch.hpp);
//   8. display: foot locking holds planted feet on the ground through
//      two-bone IK (foot_locker.hpp) on the animated pose, jumps of step 7
//      included: the displayed pose and its world joint positions.
// Deferred form tick(dt, input, async, pool): step 6 is split: the batch is
// submitted in step 6 and its results are applied (step 7) at the start of
// the next tick, before step 1 (one tick of latency), so a GPU search
// overlaps the caller's work.
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

#include "mmvk/database/animation_data.hpp"
#include "mmvk/search/async_search.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/animation/foot_locker.hpp"
#include "mmvk/animation/gait_choice.hpp"
#include "mmvk/animation/pose_batch.hpp"
#include "mmvk/query/query_assembly.hpp"
#include "mmvk/animation/root_history.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "mmvk/common/thread_pool.hpp"
#include "mmvk/animation/trajectory.hpp"

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
  // The correction removes drift, it does not carry the character: its
  // speed is also held to correction_speed_ratio times the animated root's
  // own speed this tick (orangeduck's controller holds it to half), but
  // never below min_correction_speed, so a standing character is still
  // brought to its place. Finite, > 0 and >= 0.
  float correction_speed_ratio = 0.5f;
  float min_correction_speed = 0.1f;  // m/s
  // The correction pulls in only the part of the gap beyond this (metres,
  // finite, >= 0, below max_correction_distance): the animation's own drift
  // of a few centimetres stays, instead of gliding the body to erase it.
  // 0.02 m: on the default data and Bandai under a host's commands it cut
  // the correction's share of the travel from 11% to 8%, the trajectory
  // error at 1 s 0.03-0.04 m (bench/RESULTS.md, "A dead zone in the
  // correction"); 0.03 m cut it to 7% but the README's main job missed
  // 0.05 m of trajectory error.
  float correction_dead_zone = 0.02f;
  // Speed from the animation. Each tick a character's clip plays at the
  // rate that brings its stride speed (the root's mean speed over
  // stride_window seconds about the frame) to the simulated root's speed,
  // within [min_play_rate, max_play_rate]; what the rate cannot reach is
  // made up by stride warping: the played root motion is scaled, within
  // [min_stride_scale, max_stride_scale] (planted feet are held by the foot
  // locker meanwhile). A standing frame (stride speed under 0.1 m/s) plays
  // at rate 1, unwarped, and in place (stride scale 0) while the command
  // is to stand: a standing loop's root drift does not move a character
  // told to stand. All four 1: the data's own speeds (still in place when
  // told to stand). Each bound finite and > 0, each pair ordered.
  float min_play_rate = 0.75f;
  float max_play_rate = 1.3f;
  float min_stride_scale = 0.85f;
  float max_stride_scale = 1.15f;
  float stride_window = 1.0f;  // seconds
  // Gait from the command (gait_choice.hpp): on a database with measured
  // gait tags (Database::gait_bands), each character's searches keep to the
  // frames of its commanded gait and phase: standing frames when told to
  // stand (or, with no idle in the data, it holds a frame with both feet
  // down), moving ones when told to move. Characters whose own tags
  // (query_params()) name a gait: tag, and every character with this false
  // or on a database without the tags, search as their tags say.
  bool choose_gait = true;
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
  // Seconds the tick waited on its search: the backend's search(), or the
  // AsyncSearch's submit() and collect() (wall clock).
  double search_seconds = 0.0;
};

// What a character's search was this tick (CrowdController::searched()).
enum class SearchKind : std::uint8_t {
  None = 0,     // no search
  Regular = 1,  // its timer ran out
  Forced = 2,   // placement, a clip's end, a sharp change of the desired velocity or yaw (force_search_*)
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

  std::uint32_t size() const { return characters_; }
  const Database& database() const { return *database_; }
  const AnimationData& animation() const { return *animation_; }
  const ControllerParams& params() const { return params_; }
  const TickStats& last_tick() const { return last_; }
  const TickStats& totals() const { return totals_; }
  std::uint64_t ticks() const { return ticks_; }

  // Per-character query options (tags, weights); the controller overwrites
  // continuing_frame, continuing_bias, continuing_multiplier and exclusion_window.
  std::span<QueryParams> query_params() { return schedule_.query_params; }

  // The results the last tick applied, in the order they were searched:
  // character applied_characters()[i] got applied_matches()[i] (the same
  // tick's batch for the synchronous tick, the previous tick's for the
  // deferred one; empty when none came back).
  std::span<const std::uint32_t> applied_characters() const {
    return std::span<const std::uint32_t>(applied_.characters).first(applied_.count);
  }
  std::span<const Match> applied_matches() const { return std::span<const Match>(applied_.matches).first(applied_.count); }
  // The batch the last tick searched (for the deferred tick, the one it
  // submitted): its characters, ascending, and its queries, row i for
  // character submitted_characters()[i]; views of the controller's buffers,
  // valid until its next tick.
  std::span<const std::uint32_t> submitted_characters() const {
    return std::span<const std::uint32_t>(batch_.characters).first(batch_.count);
  }
  QueryBatch submitted_batch() const { return batch_queries(); }

  // Per-character output, [B] unless noted.
  std::span<const std::uint32_t> frames() const { return playback_.frames; }       // database frame played
  std::span<const float> frame_fractions() const { return playback_.fractions; }  // of the way to the next frame, [0, 1)
  std::span<const glm::vec3> root_positions() const { return roots_.position; }   // animated root, world, y = 0
  std::span<const float> root_yaws() const { return roots_.yaw; }
  std::span<const SimulationState> simulation() const { return roots_.simulated; }  // simulated root
  std::span<const SearchKind> searched() const { return schedule_.searched; }       // this tick's search of each
  std::span<const std::uint8_t> jumped() const { return outcome_.jumped; }          // 1: jumped this tick
  std::span<const float> match_costs() const { return outcome_.match_cost; }        // last applied match (inf: none)
  // FootContact bits of the nearest frame, less those of a foot that steps
  // (settle_feet), [B].
  std::span<const std::uint8_t> contacts() const { return playback_.contacts; }
  // The gait each character was commanded into this tick and the tag
  // constraint its searches get (ControllerParams::choose_gait; empty
  // constraints where it does not apply), and 1 while, told to stand, it
  // holds a frame with both feet down: the data's rest frame where the data
  // has no idle (GaitConstraint::rest), or a standing frame of a clip that
  // goes on (not a loop) where it has (gait_choice.hpp), [B].
  std::span<const GaitState> gait_states() const { return gaits_.state; }
  std::span<const GaitConstraint> gait_constraints() const { return gaits_.constraint; }
  std::span<const std::uint8_t> resting() const { return gaits_.holding; }
  // Speed from the animation (ControllerParams::min_play_rate, ...): the
  // rate each character played its clip at this tick, and the scale of its
  // root motion, [B].
  std::span<const float> play_rates() const { return playback_.rate; }
  std::span<const float> stride_scales() const { return playback_.stride; }
  // This tick's root correction (step 3), world metres, y = 0, [B]: the
  // shown root moved by its clip's root motion plus this.
  std::span<const glm::vec3> root_corrections() const { return roots_.correction; }
  // The trajectory of each character's last search: [B x T] world positions
  // and yaws, T = trajectory_offsets().size(), predicted at that search's
  // tick (searched() != None) for the times trajectory_offsets() after it.
  std::span<const float> trajectory_offsets() const { return assembler_.trajectory_offsets(); }
  std::span<const glm::vec3> predicted_positions() const { return schedule_.predicted_positions; }
  std::span<const float> predicted_yaws() const { return schedule_.predicted_yaws; }
  // The output pose, character space: [B x joints] each.
  std::span<const glm::quat> local_rotations() const { return poses_.rotations; }
  std::span<const glm::vec3> local_translations() const { return poses_.translations; }
  // Its world joint positions, [B x joints] metres (step 8 writes them).
  std::span<const glm::vec3> world_positions() const { return poses_.world; }
  // The animated pose before foot IK (what queries measure), character
  // space, [B x joints] each, and its world joint positions [B x joints]
  // (the tick's one forward kinematics; after step 7's jumps, so always the
  // world positions of animated_rotations() and animated_translations()).
  std::span<const glm::quat> animated_rotations() const { return poses_.animated_rotations; }
  std::span<const glm::vec3> animated_translations() const { return poses_.animated_translations; }
  std::span<const glm::vec3> animated_world_positions() const { return poses_.animated_world; }
  // Foot locking (ControllerParams::foot_ik), per character and foot
  // (left, right), [B x 2]: 1 while the foot is held where it was planted;
  // the world position it is held at (metres); 1 when the leg could not
  // reach its target this tick and was soft-clamped; how far the displayed
  // foot is held from its animated pose (the lock's correction, world metres,
  // y = 0). All 0 with foot IK off.
  std::span<const std::uint8_t> foot_locked() const;
  std::span<const glm::vec3> foot_anchors() const;
  std::span<const glm::vec3> foot_corrections() const;
  std::span<const std::uint8_t> ik_reach_clamped() const;
  // The locker itself (hip drops, corrections), or null with foot IK off
  // on a skeleton without legs.
  const FootLocker* foot_locker() const { return locker_ ? &*locker_ : nullptr; }

 private:
  // Where each character is in its clip, [B].
  struct Playback {
    std::vector<std::uint32_t> frames;
    std::vector<float> fractions;            // of the way from frames to the next frame, [0, 1)
    std::vector<std::uint8_t> held;          // on a non-looping clip's last frame
    std::vector<std::uint8_t> contacts;      // FootContact bits of the nearest frame
    std::vector<glm::vec3> played_velocity;  // root velocity of the played frames, character space, m/s
    std::vector<float> played_yaw_rate;      // rad/s
    std::vector<float> rate, stride;         // this tick's play rate and stride scale
    // This tick's step along the clip's root path (character space, metres;
    // radians), which step 2 moves the root by.
    std::vector<glm::vec3> step_translation;
    std::vector<float> step_yaw;
  };
  // The animated root, the simulated root it is corrected toward, [B], and
  // the animated root's recorded path.
  struct Roots {
    std::vector<glm::vec3> position;  // world, y = 0
    std::vector<float> yaw;
    std::vector<float> start_yaw;     // the yaw at the tick's start
    std::vector<float> yaw_rate;      // the animated root's turning rate, rad/s
    std::vector<float> animated_speed;   // this tick's root motion before the correction, m/s
    std::vector<glm::vec3> correction;   // this tick's correction, world metres
    std::vector<SimulationState> simulated;
    RootHistory history;
  };
  // When each character searches and with what, [B] unless noted.
  struct Schedule {
    std::vector<float> timer;                // seconds to the next regular search
    std::vector<std::uint8_t> force;         // forced search pending (placed, first tick)
    std::vector<std::uint8_t> was_blocked;   // the nearest frame before this tick's play was in a block_transition range
    std::vector<SearchKind> due, searched;   // this tick's decision; what searched() reports
    std::vector<glm::vec3> desired_velocity, searched_velocity;
    std::vector<float> desired_yaw, searched_yaw;
    std::vector<QueryParams> query_params;
    std::vector<glm::vec3> predicted_positions;  // [B x T]
    std::vector<float> predicted_yaws;           // [B x T]
  };
  // What the applied results did, [B].
  struct Outcome {
    std::vector<std::uint8_t> jumped, suppressed;  // suppressed: within same_location_window
    std::vector<float> match_cost;
  };
  // Poses, [B x joints] unless noted.
  struct Poses {
    std::vector<glm::quat> animated_rotations;   // character space, before foot IK
    std::vector<glm::vec3> animated_translations;
    std::vector<glm::vec3> animated_world;       // their world joint positions (the one FK)
    std::vector<glm::quat> rotations;            // displayed
    std::vector<glm::vec3> translations;
    std::vector<glm::vec3> world;
    std::vector<glm::vec3> velocity_world;       // [B x V] last world positions of the assembler's velocity joints
    std::vector<glm::vec3> joint_velocities;     // [B x V] their velocities, character space
    std::vector<std::uint8_t> fresh;             // [B] placed since the last tick: no velocities yet
  };
  // The queries of one tick's due characters, [B] capacity (x dims, x past offsets).
  struct Batch {
    std::vector<std::uint32_t> characters;  // ascending
    std::vector<std::uint32_t> continuing;  // their continuing frames
    std::vector<QueryFrame> frames;
    std::vector<float> queries;
    std::vector<glm::vec3> past_positions;
    std::vector<float> past_yaws;
    std::vector<QueryParams> params;
    std::uint32_t count = 0;
  };
  // Gait from the command (gait_choice.hpp), [B] unless noted.
  struct Gaits {
    bool enabled = false;  // choose_gait on a database with measured gait tags
    GaitBandParams params;
    GaitTagBits bits;
    // What one distinct pair of a character's own masks leaves: its
    // options, and the frame to rest on in each clip ([clips]; where a clip
    // has none, the best of all).
    struct Entry {
      TagMask require = 0, exclude = 0;
      GaitOptions options;
      std::vector<std::uint32_t> rest_frames;
    };
    std::vector<Entry> entries;
    std::vector<GaitState> state;
    std::vector<GaitConstraint> constraint;
    std::vector<std::uint32_t> entry;               // into entries, for b's masks
    std::vector<TagMask> own_require, own_exclude;  // the query_params() masks entry was found for
    std::vector<std::uint8_t> own_gait;             // the masks name a gait: tag
    std::vector<std::uint8_t> first;                // no state yet (placed)
    std::vector<std::uint8_t> holding;              // resting on its rest frame
  };
  // A searched batch's characters and the frames they continued, [B]
  // capacity: the deferred batch in flight.
  struct InFlight {
    std::vector<std::uint32_t> characters, continuing;
    std::uint32_t count = 0;
  };
  // The results applied by the last tick, [B] capacity.
  struct Applied {
    std::vector<std::uint32_t> characters;
    std::vector<Match> matches;
    std::uint32_t count = 0;
  };
  // Per pool thread: a destination pose and velocities for jumps, and a
  // character-space copy of a pose's joint positions for its query.
  struct ThreadScratch {
    std::vector<glm::quat> rotations;
    std::vector<glm::vec3> translations, angular, velocities, source_angular, source_velocities, joint_positions;
  };

  CrowdController() = default;
  void size_state(std::uint32_t characters);
  Status check_input(float dt, const CrowdInput& input) const;
  void start_tick(ThreadPool& pool);
  void finish_tick();
  // Steps 1-4 over every character; fills the batch's characters.
  void advance(float dt, const CrowdInput& input, ThreadPool& pool);
  // The steps of advance() for characters [begin, end).
  void simulate_and_play(std::size_t begin, std::size_t end, float dt, const CrowdInput& input,
                         ThreadScratch& scratch);
  void blend(std::size_t begin, std::size_t end, float dt);
  void correct(std::size_t begin, std::size_t end, float dt, float fraction);
  void decide(std::size_t begin, std::size_t end, float dt);
  // Serially before step 1: each character's gait entry, for its current
  // query_params() masks.
  void refresh_gait_options();
  // At create(): whether gaits are chosen, and every character's entry for
  // its first (empty) masks.
  void start_gaits();
  std::uint32_t gait_entry(TagMask require, TagMask exclude);
  // Step 1's gait: b's state and constraint this tick, and its rest: it
  // jumps to its rest frame and holds it. Returns whether b holds a frame
  // (plays at rate 0).
  bool choose_gait(std::size_t b, float dt, ThreadScratch& scratch);
  // b's foot locked far from where its pose puts it steps there (11 cm
  // standing, 10 cm moving); the contacts shown lose a stepping foot's bits.
  void settle_feet(std::uint32_t b);
  // The one forward kinematics of b's animated pose, and the velocities of
  // the joints queries read; `fresh`: no previous tick.
  void measure(std::uint32_t b, float dt, bool fresh);
  // Step 5 for the batch's characters.
  void assemble(ThreadPool& pool);
  QueryBatch batch_queries() const;
  // Step 7: applied_'s matches, whose queries continued continuing[count].
  void apply(std::span<const std::uint32_t> continuing, ThreadPool& pool);
  bool same_location(std::uint32_t b, std::uint32_t to) const;
  void jump(std::uint32_t b, std::uint32_t to, ThreadScratch& scratch);
  // Step 8 for every character; `after_jumps`: step 7 ran after step 3, so
  // the characters that jumped are measured again.
  void display(float dt, bool after_jumps, ThreadPool& pool);
  void display(std::uint32_t b, float dt);
  void ensure_scratch(unsigned threads);

  const Database* database_ = nullptr;
  const AnimationData* animation_ = nullptr;
  ControllerParams params_;
  std::vector<float> stride_speeds_;  // [frames] m/s (play_rate.hpp), made once
  QueryAssembler assembler_;
  Inertializer inertializer_;
  std::uint32_t characters_ = 0;
  std::uint32_t joints_ = 0;
  std::uint32_t trajectory_size_ = 0;
  std::uint64_t ticks_ = 0;
  TickStats last_, totals_;

  Playback playback_;
  Roots roots_;
  Schedule schedule_;
  Outcome outcome_;
  Poses poses_;
  Gaits gaits_;
  Batch batch_;
  InFlight in_flight_;
  Applied applied_;
  std::optional<FootLocker> locker_;
  std::vector<std::uint8_t> no_feet_flags_;  // [B x 2] zeros, without a locker
  std::vector<glm::vec3> no_feet_vectors_;   // [B x 2] zeros: anchors and corrections without foot IK
  std::vector<ThreadScratch> scratch_;
};

}  // namespace mmvk
