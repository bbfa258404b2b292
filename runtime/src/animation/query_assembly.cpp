// Batched query assembly (query_assembly.hpp): the schema is turned once into
// copy runs and trajectory slots.
#include "mmvk/query_assembly.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "mmvk/channel_kinds.hpp"

namespace mmvk {

Result<QueryAssembler> QueryAssembler::create(const Database& database) {
  const FeatureSchema& schema = database.schema();
  QueryAssembler out;
  out.database_ = &database;
  out.dims_ = database.dims();
  bool has_positions = false;
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    const std::uint32_t first = schema.offset(c);
    // Channels with trajectory offsets are filled from the prediction (the
    // kind table says which); every other channel is copied from the frame.
    const bool trajectory = uses_trajectory_offsets(channel.kind);
    has_positions = has_positions || channel.kind == ChannelKind::TrajectoryPosition;
    // Adjacent copied dims merge into one copy run.
    const auto copy = [&](std::uint32_t begin, std::uint32_t count) {
      if (!out.copies_.empty() && out.copies_.back().begin + out.copies_.back().count == begin) {
        out.copies_.back().count += count;
      } else {
        out.copies_.push_back({begin, count});
      }
    };
    if (!trajectory) {
      copy(first, channel.dims());
      continue;
    }
    for (std::size_t i = 0; i < channel.offsets_seconds.size(); ++i) {
      const float t = channel.offsets_seconds[i];
      // The past trajectory is the path the character's current frame came
      // along, so it is copied from the frame like the pose.
      if (t < 0.0f) {
        copy(first + 2 * static_cast<std::uint32_t>(i), 2);
      } else if (std::find(out.offsets_.begin(), out.offsets_.end(), t) == out.offsets_.end()) {
        out.offsets_.push_back(t);
      }
    }
  }
  if (!has_positions) {
    return make_error("query assembly: the database's schema has no trajectory_position channel, which the "
                      "controller's trajectory predictor fills; rebuild with a schema that has one (the default "
                      "schema does)");
  }
  std::sort(out.offsets_.begin(), out.offsets_.end());
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    if (!uses_trajectory_offsets(channel.kind)) continue;
    std::uint32_t dim = schema.offset(c);
    for (float t : channel.offsets_seconds) {
      if (t < 0.0f) {
        dim += 2;
        continue;
      }
      const auto index = static_cast<std::uint32_t>(std::find(out.offsets_.begin(), out.offsets_.end(), t) -
                                                    out.offsets_.begin());
      out.slots_.push_back({dim, index, channel.kind == ChannelKind::TrajectoryDirection});
      dim += 2;
    }
  }
  out.scale_.resize(out.dims_);
  out.offset_.resize(out.dims_);
  for (std::uint32_t d = 0; d < out.dims_; ++d) {
    out.scale_[d] = database.normalization()[d].scale;
    out.offset_[d] = database.normalization()[d].offset;
  }
  return out;
}

void QueryAssembler::assemble(std::uint32_t frame, const QueryFrame& reference, std::span<const glm::vec3> positions,
                              std::span<const float> yaws, std::span<float> out) const {
  assert(out.size() >= dims_ && positions.size() >= offsets_.size() && yaws.size() >= offsets_.size());
  const float* row = database_->features().data() + std::size_t{frame} * dims_;
  for (const Copy& copy : copies_) std::copy_n(row + copy.begin, copy.count, out.data() + copy.begin);
  // Character space of the reference: the inverse yaw rotation.
  const float c = std::cos(reference.root_yaw);
  const float s = std::sin(reference.root_yaw);
  for (const Slot& slot : slots_) {
    float x = 0.0f;
    float z = 0.0f;
    if (slot.direction) {
      const float relative = yaws[slot.offset_index] - reference.root_yaw;
      x = std::sin(relative);
      z = std::cos(relative);
    } else {
      const glm::vec3 d = positions[slot.offset_index] - reference.root_position;
      x = d.x * c - d.z * s;
      z = d.x * s + d.z * c;
    }
    const std::uint32_t i = slot.dim;
    // Divided, not multiplied by an inverse: the same bits as Database::normalize.
    out[i] = (x - offset_[i]) / scale_[i];
    out[i + 1] = (z - offset_[i + 1]) / scale_[i + 1];
  }
}

void QueryAssembler::assemble_batch(std::span<const std::uint32_t> frames, std::span<const QueryFrame> references,
                                    std::span<const glm::vec3> positions, std::span<const float> yaws,
                                    std::span<float> out) const {
  const std::size_t t = offsets_.size();
  assert(references.size() >= frames.size() && positions.size() >= frames.size() * t &&
         yaws.size() >= frames.size() * t && out.size() >= frames.size() * dims_);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    assemble(frames[i], references[i], positions.subspan(i * t, t), yaws.subspan(i * t, t),
             out.subspan(i * dims_, dims_));
  }
}

}  // namespace mmvk
