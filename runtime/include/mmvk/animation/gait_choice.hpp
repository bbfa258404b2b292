// The gait a character searches in, chosen from its command: stand, start,
// move (walk, jog, run) and stop, from the desired speed and the simulated
// root's speed, each search constrained to the database's measured gait tags
// (gait_bands.hpp) that fit. The CrowdController runs it per character and
// tick (ControllerParams::choose_gait); the functions are pure, for tests.
//
// The rule:
//   1. band: the commanded (desired) horizontal speed banded with the
//      database's own thresholds and hysteresis (GaitBandParams: a band is
//      left upwards only at the next threshold x (1 + hysteresis), downwards
//      only under its own threshold x (1 - hysteresis)), so a command that
//      wavers about a threshold does not flicker between gaits;
//   2. phase: Stand while the band is stand and the simulated root is under
//      walk_from_mps; Stop while the band is stand and it still moves;
//      Start from Stand when the band leaves stand, for transition_seconds
//      or until the simulated root reaches 90% of the command; Move after;
//   3. constraint, only on the frames the character's own tags allow (a
//      host's or scenario's tags stay: a style, a mood):
//      - Stand: the stand frames, where those tags leave an idle (a looping
//        clip that stands, or kMinIdleSeconds of standing frames); else no
//        frame constraint, and the character rests: it plays on to a frame
//        with both feet down and holds it (its feet locked), since walking
//        in place is worse than holding still;
//      - Stop: none (the predicted trajectory, which slows to rest, picks the
//        data's stops where it has them);
//      - Start: no standing frame (the character must leave its idle) and
//        no stop;
//      - Move: the commanded band and its moving neighbours (walk: walk and
//        jog; jog: all three; run: jog and run), never a standing frame nor
//        a stop (a stop's slow end is no slow walk: it would stop over and
//        over, and a clip that stops is left when its stop begins). A
//        band's neighbours are allowed because the data's bands are measured
//        per frame with their own hysteresis: a jog clip dips into walk
//        speed in places, and forbidding that would cut it into pieces.
//        Where those tags leave none of the allowed bands, only standing
//        and stops are excluded.
//   A character whose own tags name a gait: tag chooses for itself: the
//   controller adds nothing.
#pragma once

#include <array>
#include <cstdint>

#include "mmvk/database/database.hpp"
#include "mmvk/database/gait_bands.hpp"
#include "mmvk/database/gait_coverage.hpp"

namespace mmvk {

enum class GaitPhase : std::uint8_t { Stand, Start, Move, Stop };

struct GaitState {
  GaitBand band = GaitBand::Stand;  // of the command
  GaitPhase phase = GaitPhase::Stand;
  float phase_seconds = 0.0f;  // time in this phase
};

// What the frames allowed by a character's own tags can do.
struct GaitOptions {
  std::array<bool, kGaitBandCount> band{};  // a candidate frame in each band
  bool idle = false;                        // GaitCoverage::can_stand()
};
GaitOptions gait_options(const GaitCoverage& coverage);

// The first state of a character commanded `commanded_speed`: its band
// without hysteresis, Stand or Move.
GaitState first_gait_state(const GaitBandParams& params, float commanded_speed);

// One tick of the rule's steps 1 and 2 (speeds in m/s, dt seconds > 0).
GaitState next_gait_state(const GaitBandParams& params, const GaitState& state, float commanded_speed,
                          float simulated_speed, float dt);

struct GaitConstraint {
  TagMask require_all = 0;
  TagMask exclude_any = 0;
  bool rest = false;  // hold a frame with both feet down (no idle to stand on)
  friend bool operator==(const GaitConstraint&, const GaitConstraint&) = default;
};

// Step 3 for one state and the options its tags leave.
GaitConstraint gait_constraint(const GaitState& state, const GaitOptions& options, const GaitTagBits& bits);

}  // namespace mmvk
