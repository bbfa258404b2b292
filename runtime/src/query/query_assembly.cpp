// Batched query assembly (query_assembly.hpp): the schema is turned once into
// copy runs and trajectory slots.
#include "mmvk/query/query_assembly.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <glm/geometric.hpp>

#include "mmvk/features/channel_kinds.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/features/foot_contacts.hpp"

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
  if (database.animation() != nullptr) {
    if (Status planned = out.plan_shown(database); !planned.ok()) return make_error(planned.message());
  }
  return out;
}

Status QueryAssembler::plan_shown(const Database& database) {
  const FeatureSchema& schema = database.schema();
  const Skeleton& skeleton = database.animation()->skeleton;
  parents_ = skeleton.parents;
  auto resolve = [&](const std::string& bone, const FeatureChannel& channel, const char* field) -> Result<int> {
    Result<int> joint = find_bone(skeleton, bone);
    if (!joint.ok()) return make_error("query assembly: channel '" + channel.name + "': " + field + ": " + joint.message());
    return joint;
  };
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& channel = schema.channels[c];
    const ChannelKindInfo& info = channel_kind_info(channel.kind);
    const std::uint32_t first = schema.offset(c);
    const std::string bone = channel.bone.empty() ? std::string(info.default_bone) : channel.bone;
    Measure m;
    m.dim = first;
    switch (info.shown) {
      case ShownSource::Trajectory:
        for (std::size_t i = 0; i < channel.offsets_seconds.size(); ++i) {
          if (channel.offsets_seconds[i] >= 0.0f) continue;
          // The build sampled the past at whole frames: so does the query.
          const float ago =
              -float(signed_offset_frames(channel.offsets_seconds[i], database.fps())) / database.fps();
          auto found = std::find(past_offsets_.begin(), past_offsets_.end(), ago);
          if (found == past_offsets_.end()) found = past_offsets_.insert(past_offsets_.end(), ago);
          past_slots_.push_back({first + 2 * static_cast<std::uint32_t>(i),
                                 static_cast<std::uint32_t>(found - past_offsets_.begin()),
                                 channel.kind == ChannelKind::TrajectoryDirection});
        }
        continue;
      case ShownSource::JointPosition: {
        MMVK_ASSIGN_OR_RETURN(m.joint, resolve(bone, channel, "bone"));
        m.source = ShownSource::JointPosition;
        break;
      }
      case ShownSource::JointVelocity: {
        MMVK_ASSIGN_OR_RETURN(const int joint, resolve(bone, channel, "bone"));
        auto found = std::find(velocity_joints_.begin(), velocity_joints_.end(), joint);
        if (found == velocity_joints_.end()) found = velocity_joints_.insert(velocity_joints_.end(), joint);
        m.source = ShownSource::JointVelocity;
        m.index = static_cast<std::uint32_t>(found - velocity_joints_.begin());
        break;
      }
      case ShownSource::Limb: {
        MMVK_ASSIGN_OR_RETURN(m.joint, resolve(bone, channel, "bone"));
        MMVK_ASSIGN_OR_RETURN(m.second_joint, resolve(channel.second_bone, channel, "second_bone"));
        m.source = ShownSource::Limb;
        break;
      }
      case ShownSource::YawRate:
      case ShownSource::Contacts:
        m.source = info.shown;
        break;
      case ShownSource::Row: {
        const std::uint32_t count = channel.dims();
        if (!shown_copies_.empty() && shown_copies_.back().begin + shown_copies_.back().count == first) {
          shown_copies_.back().count += count;
        } else {
          shown_copies_.push_back({first, count});
        }
        continue;
      }
    }
    measures_.push_back(m);
  }
  measures_shown_ = true;
  return {};
}

namespace {

// Character space of a reference root: the inverse yaw rotation.
glm::vec3 to_reference(const glm::vec3& world_offset, float c, float s) {
  return {world_offset.x * c - world_offset.z * s, world_offset.y, world_offset.x * s + world_offset.z * c};
}

}  // namespace

void QueryAssembler::write_slots(std::span<const Slot> slots, const QueryFrame& reference,
                                 std::span<const glm::vec3> positions, std::span<const float> yaws,
                                 std::span<float> out) const {
  const float c = std::cos(reference.root_yaw);
  const float s = std::sin(reference.root_yaw);
  for (const Slot& slot : slots) {
    float x = 0.0f;
    float z = 0.0f;
    if (slot.direction) {
      const float relative = yaws[slot.offset_index] - reference.root_yaw;
      x = std::sin(relative);
      z = std::cos(relative);
    } else {
      const glm::vec3 d = to_reference(positions[slot.offset_index] - reference.root_position, c, s);
      x = d.x;
      z = d.z;
    }
    write(slot.dim, x, out);
    write(slot.dim + 1, z, out);
  }
}

void QueryAssembler::assemble(std::uint32_t frame, const QueryFrame& reference, std::span<const glm::vec3> positions,
                              std::span<const float> yaws, std::span<float> out) const {
  assert(out.size() >= dims_ && positions.size() >= offsets_.size() && yaws.size() >= offsets_.size());
  const float* row = database_->features().data() + std::size_t{frame} * dims_;
  for (const Copy& copy : copies_) std::copy_n(row + copy.begin, copy.count, out.data() + copy.begin);
  write_slots(slots_, reference, positions, yaws, out);
}

void QueryAssembler::assemble_shown(const ShownPose& shown, const QueryFrame& reference,
                                    std::span<const glm::vec3> positions, std::span<const float> yaws,
                                    std::span<float> out) const {
  assert(measures_shown_ && out.size() >= dims_ && positions.size() >= offsets_.size() &&
         yaws.size() >= offsets_.size() && shown.past_positions.size() >= past_offsets_.size() &&
         shown.past_yaws.size() >= past_offsets_.size() && shown.joint_velocities.size() >= velocity_joints_.size());
  const float* row = database_->features().data() + std::size_t{shown.frame} * dims_;
  for (const Copy& copy : shown_copies_) std::copy_n(row + copy.begin, copy.count, out.data() + copy.begin);
  write_slots(slots_, reference, positions, yaws, out);
  write_slots(past_slots_, reference, shown.past_positions, shown.past_yaws, out);
  const auto xyz = [&](std::uint32_t dim, const glm::vec3& v) {
    write(dim, v.x, out);
    write(dim + 1, v.y, out);
    write(dim + 2, v.z, out);
  };
  const std::span<const glm::vec3> joints = shown.joint_positions;
  for (const Measure& m : measures_) {
    switch (m.source) {
      case ShownSource::Trajectory:
      case ShownSource::Row:
        break;  // planned as slots and copies
      case ShownSource::JointPosition:
        xyz(m.dim, joints[static_cast<std::size_t>(m.joint)]);
        break;
      case ShownSource::JointVelocity:
        xyz(m.dim, shown.joint_velocities[m.index]);
        break;
      case ShownSource::Limb: {
        // As extracted: the chain's length summed bone by bone, so the
        // vector says how far the limb is stretched.
        float length = 0.0f;
        for (int j = m.second_joint; j != m.joint && j >= 0; j = parents_[static_cast<std::size_t>(j)]) {
          const int parent = parents_[static_cast<std::size_t>(j)];
          if (parent < 0) break;
          length += glm::length(joints[static_cast<std::size_t>(j)] - joints[static_cast<std::size_t>(parent)]);
        }
        const glm::vec3 limb = joints[static_cast<std::size_t>(m.second_joint)] - joints[static_cast<std::size_t>(m.joint)];
        xyz(m.dim, length > 0.0f ? limb / length : glm::vec3(0.0f));
        break;
      }
      case ShownSource::YawRate:
        write(m.dim, shown.yaw_rate, out);
        break;
      case ShownSource::Contacts:
        write(m.dim, (shown.contacts & kContactLeft) != 0 ? 1.0f : 0.0f, out);
        write(m.dim + 1, (shown.contacts & kContactRight) != 0 ? 1.0f : 0.0f, out);
        break;
    }
  }
}

}  // namespace mmvk
