// What a crowd run records for the viewer: plain data, filled by the
// simulation while it runs and read by write_viewer_html() afterwards. No
// behaviour lives here, so the simulation and the viewer only share this
// layout.
//
// Conventions (the same as the runtime's character root):
// - World space is Y-up, metres; the ground is the XZ plane (y = 0).
// - A facing is a yaw angle in radians about +Y: facing 0 looks along +Z and
//   facing f looks along (sin f, 0, cos f).
// - Character space is the frame of the character root: origin on the
//   ground under the hips, +Z forward, +Y up. A point p in character space
//   of an agent at root (x, z) with facing f is, in world space,
//   (x + cos f * p.x + sin f * p.z,  p.y,  z - sin f * p.x + cos f * p.z).
// - Times are seconds from the start of the run.
// - Flat arrays are row-major with the shapes written beside them; the
//   index helpers at the end compute their offsets.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace mmvk::crowd {

// One motion-matching search of one agent.
struct SearchEvent {
  float time_s = 0.0f;      // when the search ran
  bool jumped = false;      // true when the controller transitioned to to_frame
  bool forced = false;      // a forced search (e.g. a sharp goal change), not a scheduled one
  int32_t from_frame = -1;  // database frame playing when the search ran
  int32_t to_frame = -1;    // best match found (equals the continuation when not jumped); -1: no candidate
  float cost = 0.0f;        // the match's cost (the search's distance, unitless)
};

// A change of one agent's feet: the state from time_s on.
struct FootEvent {
  float time_s = 0.0f;
  // Bit 0 / 1: the left / right foot is flagged planted (the played frame's
  // contact); bit 2 / 3: the left / right foot is locked (held by foot IK).
  std::uint8_t state = 0;
  // Where each locked foot is held (left, right), world metres; (0, 0, 0)
  // for a foot that is not locked.
  std::array<std::array<float, 3>, 2> anchor{};
};
inline constexpr std::uint8_t kFootPlantedLeft = 1, kFootPlantedRight = 2, kFootLockedLeft = 4, kFootLockedRight = 8;

struct Recording {
  // Shown in the page's header, e.g. "1000 agents, vulkan (llvmpipe), bandai".
  std::string title;

  // --- the sampled state ------------------------------------------------
  // The simulation records every agent at this rate (it need not equal the
  // simulation rate; 10 to 30 Hz is plenty for the viewer).
  float sample_rate_hz = 10.0f;
  std::size_t agent_count = 0;
  std::size_t sample_count = 0;

  // [sample_count x agent_count], metres: the root's ground position.
  std::vector<float> root_x;
  std::vector<float> root_z;
  // [sample_count x agent_count], radians (see the facing convention above).
  std::vector<float> facing;
  // [sample_count x agent_count]: the database frame playing at the sample
  // (-1 when none). Poses are drawn from pose_positions for these frames.
  std::vector<int32_t> frame;

  // The desired trajectory the controller searched with at each sample:
  // trajectory_times_s.size() future points per agent, in world space
  // (metres). trajectory_times_s are seconds ahead of the sample, ascending
  // and positive (e.g. {0.333, 0.667, 1.0}).
  std::vector<float> trajectory_times_s;
  // [sample_count x agent_count x trajectory_times_s.size()], metres.
  std::vector<float> desired_x;
  std::vector<float> desired_z;
  // The trajectory the database offered at the matched frame, same shape and
  // points in world space; may be left empty. (The path the agent actually
  // walked is root_x/root_z over the following samples.)
  std::vector<float> matched_x;
  std::vector<float> matched_z;

  // --- per agent ---------------------------------------------------------
  // [agent_count][goals] the goal points each agent walks to, in order,
  // metres (x, z).
  struct Goal {
    float x = 0.0f;
    float z = 0.0f;
  };
  std::vector<std::vector<Goal>> goals;
  // [agent_count][events] every search of each agent, in time order.
  std::vector<std::vector<SearchEvent>> searches;

  // --- the skeleton and the poses that were played -----------------------
  // [joint_count] joint names and parent indices (-1 for a root; a parent
  // index is always smaller than its child's).
  std::vector<std::string> joint_names;
  std::vector<int32_t> joint_parents;
  // The database frames whose poses are recorded (ascending, unique), and
  // [pose_frames.size() x joint_count x 3] their joint positions in
  // character space (metres, x y z), computed with forward kinematics.
  // Record every frame that appears in `frame` (frames missing here are
  // drawn without a skeleton).
  std::vector<int32_t> pose_frames;
  std::vector<float> pose_positions;

  // --- the feet as displayed (optional: both empty when not recorded) -----
  // The joints foot IK moves (each leg's knee, ankle and toe, where the
  // skeleton has them), ascending; at each sample their displayed world
  // positions (after foot IK) replace the played frame's, and the joints
  // below them (end sites) move with them.
  std::vector<int32_t> leg_joints;
  // [sample_count x agent_count x leg_joints.size() x 3], world metres.
  std::vector<float> leg_positions;
  // [agent_count][events] (or empty): every change of each agent's feet, in
  // time order, the first at time 0.
  std::vector<std::vector<FootEvent>> foot_events;

  // --- the whole displayed pose at the tick rate, for a few characters ----
  // The 10 Hz samples above pose a character from its played frame with the
  // legs as displayed; the characters `detail_agents` (ascending, unique,
  // each below agent_count; any set, by default the first 32) are also
  // recorded after every tick (at `detail_rate_hz`, the simulation's rate)
  // with every joint as displayed (after foot IK), upper body included.
  // Empty when not recorded.
  float detail_rate_hz = 0.0f;
  std::vector<std::uint32_t> detail_agents;
  std::size_t detail_sample_count = 0;
  // [detail_sample_count x detail_agents.size() x joint_count x 3], world
  // metres, slot i holding character detail_agents[i]; detail sample k is
  // the state after tick k, at time k / detail_rate_hz.
  std::vector<float> detail_positions;

  // --- why each search of the detailed characters chose its frame --------
  // One frame's cost in one search, channel by channel, as mmvk's
  // explain_query() computes it from the query and the database's
  // normalized features (mmvk/search/explain.hpp: FrameExplanation).
  struct FrameWhy {
    std::int32_t frame = -1;  // database frame; -1: none (no candidate, or no continuing frame)
    std::uint32_t clip = 0;   // index into clip_names
    float clip_time_s = 0.0f; // the frame's time in its clip, seconds
    std::vector<float> weighted;  // [channel_names] weight x sum of squared differences
    float multiplier = 1.0f;  // the clip's cost multiplier
    float bias = 0.0f;        // the clip's cost bias
    float cost = 0.0f;        // the frame's cost: multiplier x sum + bias, then the continuing terms
    // Why the frame is not a candidate: an index into exclusion_names (0:
    // it is one; mmvk::Exclusion).
    std::uint8_t exclusion = 0;
  };
  struct SearchWhy {
    std::size_t search = 0;  // index into searches[agent]
    std::vector<float> weights;  // [channel_names] the query's channel weights
    float continuing_bias = 0.0f;        // the query's (QueryParams), applied to the continuing frame
    float continuing_multiplier = 1.0f;
    FrameWhy chosen, continuing;
  };
  std::vector<std::string> channel_names;  // the schema's, in order
  std::vector<std::string> clip_names;     // the database's, in order
  std::vector<std::string> exclusion_names;  // mmvk::exclusion_name() of each Exclusion, in order
  // [agent_count][explained searches] (empty lists for characters not
  // detailed), or empty when not recorded.
  std::vector<std::vector<SearchWhy>> why;

  std::size_t joint_count() const { return joint_parents.size(); }
  std::size_t trajectory_points() const { return trajectory_times_s.size(); }

  // Offsets into the flat arrays.
  std::size_t sample_index(std::size_t sample, std::size_t agent) const {
    return sample * agent_count + agent;
  }
  std::size_t trajectory_index(std::size_t sample, std::size_t agent, std::size_t point) const {
    return (sample * agent_count + agent) * trajectory_points() + point;
  }
  std::size_t pose_index(std::size_t pose, std::size_t joint) const {
    return (pose * joint_count() + joint) * 3;
  }
  std::size_t leg_index(std::size_t sample, std::size_t agent, std::size_t leg_joint) const {
    return ((sample * agent_count + agent) * leg_joints.size() + leg_joint) * 3;
  }
  // `slot`: an index into detail_agents, not a character.
  std::size_t detail_index(std::size_t sample, std::size_t slot, std::size_t joint) const {
    return ((sample * detail_agents.size() + slot) * joint_count() + joint) * 3;
  }
};

}  // namespace mmvk::crowd
