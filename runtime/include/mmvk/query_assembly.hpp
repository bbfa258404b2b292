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
//     future offsets of all trajectory channels: trajectory_offsets(). Past
//     offsets (< 0) are copied from the current frame's row, like the pose.
//   - Every other channel (bone positions and velocities, root velocity,
//     custom): the normalized values of the character's current database
//     frame, copied from the feature row (as orangeduck's Motion-Matching
//     does; the row is the pose the character is showing minus the blend).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "mmvk/database.hpp"
#include "mmvk/status.hpp"

namespace mmvk {

// The character-space frame a query is expressed in.
struct QueryFrame {
  glm::vec3 root_position{0.0f};  // world, metres
  float root_yaw = 0.0f;          // radians
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

  // One query into out[dims]: pose channels from database frame `frame`,
  // trajectory channels from predicted world positions and yaws
  // [trajectory_offsets().size()], relative to `frame_of_reference`.
  void assemble(std::uint32_t frame, const QueryFrame& frame_of_reference, std::span<const glm::vec3> positions,
                std::span<const float> yaws, std::span<float> out) const;

  // B queries: query i from frames[i], references[i] and the trajectory rows
  // positions/yaws [i*T, i*T + T) with T = trajectory_offsets().size(), into
  // out [B x dims].
  void assemble_batch(std::span<const std::uint32_t> frames, std::span<const QueryFrame> references,
                      std::span<const glm::vec3> positions, std::span<const float> yaws, std::span<float> out) const;

 private:
  struct Slot {             // one trajectory dimension pair (x, z)
    std::uint32_t dim = 0;  // first of the two dims
    std::uint32_t offset_index = 0;
    bool direction = false;
  };
  struct Copy {             // a run of dims copied from the frame's row
    std::uint32_t begin = 0;
    std::uint32_t count = 0;
  };
  const Database* database_ = nullptr;
  std::uint32_t dims_ = 0;
  std::vector<float> offsets_;
  std::vector<Slot> slots_;
  std::vector<Copy> copies_;
  std::vector<float> scale_;      // [dims]
  std::vector<float> offset_;     // [dims]
};

}  // namespace mmvk
