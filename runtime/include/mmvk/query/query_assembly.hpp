// Batched query assembly: writes B normalized queries into a caller's
// [B x dims] span for a crowd. The schema is resolved once at creation
// (each channel's first dimension, its source, its trajectory offset slots
// and the normalization), so assembling a query is plain copies and
// multiply-adds: no string compare, no allocation.
//
// Where each channel's values come from:
//   - TrajectoryPosition / TrajectoryDirection: the character's predicted
//     trajectory (trajectory.hpp), turned into its current character space
//     (origin = its root position, +Z = its facing) and normalized with the
//     database's offsets and scales. The predictor fills the distinct
//     future offsets of all trajectory channels: trajectory_offsets().
//   - From what the character shows (assemble_shown): past offsets (< 0)
//     from where its root actually was (past_offsets(), RootHistory), and the
//     pose channels measured on its displayed pose: bone positions and limb
//     vectors from its joint positions, bone and root velocities from its
//     joints' motion (velocity_joints()), the root's turning rate, its foot
//     contacts. Channels a pose cannot give (custom sidecars, phase) are
//     copied from the row of its nearest database frame.
//   - From a stored frame (assemble): past offsets and every pose channel
//     are copied from the frame's feature row (as orangeduck's
//     Motion-Matching does), for callers that have no displayed pose.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/common/status.hpp"

namespace mmvk {

// The character-space frame a query is expressed in.
struct QueryFrame {
  glm::vec3 root_position{0.0f};  // world, metres
  float root_yaw = 0.0f;          // radians
};

// What a character shows now, for assemble_shown.
struct ShownPose {
  // The database frame nearest its playback time: channels a pose cannot
  // give (custom, phase) are copied from this frame's row.
  std::uint32_t frame = 0;
  std::span<const glm::vec3> joint_positions;  // [joints] character space, metres (its displayed pose)
  std::span<const glm::vec3> joint_velocities;  // [velocity_joints().size()] character space, m/s
  float yaw_rate = 0.0f;                        // rad/s, positive turning left (towards +X)
  std::uint8_t contacts = 0;                    // FootContact bits
  std::span<const glm::vec3> past_positions;    // [past_offsets().size()] world root positions, metres
  std::span<const float> past_yaws;             // [past_offsets().size()] radians
};

class QueryAssembler {
 public:
  // Errors: the schema has no TrajectoryPosition channel (the controller's
  // predictor fills it), or a channel has a kind the assembler cannot fill
  // (the message names the channel). `database` must outlive the assembler.
  static Result<QueryAssembler> create(const Database& database);

  std::uint32_t dims() const { return dims_; }
  // The distinct trajectory offsets (seconds, ascending) the predictor must fill.
  std::span<const float> trajectory_offsets() const { return offsets_; }
  // The distinct past offsets, as seconds ago (> 0, ascending), whose root
  // poses assemble_shown reads.
  std::span<const float> past_offsets() const { return past_offsets_; }
  // The joints whose velocities assemble_shown reads, in ShownPose order.
  std::span<const int> velocity_joints() const { return velocity_joints_; }
  // The database has an animation section, so assemble_shown can resolve
  // its channels' bones (create() checked them).
  bool measures_shown_poses() const { return measures_shown_; }

  // One query into out[dims] from what the character shows (see above) and
  // its predicted trajectory [trajectory_offsets().size()], relative to
  // `frame_of_reference`. Precondition: measures_shown_poses().
  void assemble_shown(const ShownPose& shown, const QueryFrame& frame_of_reference,
                      std::span<const glm::vec3> positions, std::span<const float> yaws, std::span<float> out) const;

  // One query into out[dims]: pose channels from database frame `frame`,
  // trajectory channels from predicted world positions and yaws
  // [trajectory_offsets().size()], relative to `frame_of_reference`.
  void assemble(std::uint32_t frame, const QueryFrame& frame_of_reference, std::span<const glm::vec3> positions,
                std::span<const float> yaws, std::span<float> out) const;

 private:
  struct Slot {             // one trajectory dimension pair (x, z)
    std::uint32_t dim = 0;  // first of the two dims
    std::uint32_t offset_index = 0;
    bool direction = false;
  };
  // One pose channel measured on a shown pose.
  struct Measure {
    ShownSource source = ShownSource::JointPosition;
    std::uint32_t dim = 0;    // first dim
    int joint = -1;           // Position: the joint; Limb: the limb's root
    int second_joint = -1;    // Limb: the limb's end
    std::uint32_t index = 0;  // Velocity: into velocity_joints_
  };
  Status plan_shown(const Database& database);
  // Normalizes value into out[dim]. Divided, not multiplied by an inverse:
  // the same bits as Database::normalize.
  void write(std::uint32_t dim, float value, std::span<float> out) const {
    out[dim] = (value - offset_[dim]) / scale_[dim];
  }
  void write_slots(std::span<const Slot> slots, const QueryFrame& reference, std::span<const glm::vec3> positions,
                   std::span<const float> yaws, std::span<float> out) const;

  struct Copy {             // a run of dims copied from the frame's row
    std::uint32_t begin = 0;
    std::uint32_t count = 0;
  };
  const Database* database_ = nullptr;
  std::uint32_t dims_ = 0;
  std::vector<float> offsets_;
  std::vector<Slot> slots_;
  std::vector<Copy> copies_;
  // assemble_shown's plan: the past slots (offset_index into past_offsets_),
  // the measured channels and the runs still copied from the row.
  bool measures_shown_ = false;
  std::vector<float> past_offsets_;
  std::vector<Slot> past_slots_;
  std::vector<Measure> measures_;
  std::vector<int> velocity_joints_;
  std::vector<int> parents_;  // the skeleton's, for limb lengths
  std::vector<Copy> shown_copies_;
  std::vector<float> scale_;      // [dims]
  std::vector<float> offset_;     // [dims]
};

}  // namespace mmvk
