#include "output/crowd_recorder.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "mmvk/import/character.hpp"
#include "mmvk/animation/pose_batch.hpp"

namespace mmvk::crowd {

namespace {

// The dims of the trajectory_position channel whose offsets are exactly the
// controller's trajectory offsets, one per offset; empty when none matches.
std::vector<std::uint32_t> matched_trajectory_dims(const Database& database, std::span<const float> offsets) {
  const FeatureSchema& schema = database.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& ch = schema.channels[c];
    if (ch.kind != ChannelKind::TrajectoryPosition || ch.offsets_seconds.size() != offsets.size()) continue;
    if (!std::equal(offsets.begin(), offsets.end(), ch.offsets_seconds.begin())) continue;
    std::vector<std::uint32_t> dims;
    for (std::size_t i = 0; i < offsets.size(); ++i) dims.push_back(schema.offset(c) + std::uint32_t(2 * i));
    return dims;
  }
  return {};
}

// The joints foot IK moves: each leg's knee, ankle and toe that resolve.
std::vector<std::int32_t> ik_leg_joints(const Skeleton& skeleton) {
  std::vector<std::int32_t> joints;
  for (const char* role : {"@left_lower_leg", "@left_foot", "@left_toe", "@right_lower_leg", "@right_foot",
                           "@right_toe"}) {
    if (Result<int> joint = find_bone(skeleton, role)) joints.push_back(*joint);
  }
  std::sort(joints.begin(), joints.end());
  joints.erase(std::unique(joints.begin(), joints.end()), joints.end());
  return joints;
}

// A locked foot whose anchor moved further than this starts a new event.
constexpr float kAnchorMoveM = 0.001f;

}  // namespace

CrowdRecorder::CrowdRecorder(const CrowdController& controller, const Scenario& scenario, std::string title, float dt,
                             std::uint32_t ticks_per_sample, std::vector<std::uint32_t> detail_agents)
    : controller_(controller),
      dt_(dt),
      ticks_per_sample_(std::max<std::uint32_t>(1, ticks_per_sample)),
      why_(controller.database(), detail_agents, controller.size()) {
  Recording& r = recording_;
  r.title = std::move(title);
  r.sample_rate_hz = 1.0f / (dt * float(ticks_per_sample_));
  r.agent_count = controller.size();
  const auto offsets = controller.trajectory_offsets();
  r.trajectory_times_s.assign(offsets.begin(), offsets.end());
  r.goals.resize(r.agent_count);
  for (std::size_t a = 0; a < r.agent_count && a < scenario.agents.size(); ++a) {
    for (const auto& goal : scenario.agents[a].goals) r.goals[a].push_back({goal[0], goal[1]});
  }
  r.searches.resize(r.agent_count);
  const Skeleton& skeleton = controller.animation().skeleton;
  r.joint_names = skeleton.names;
  r.joint_parents.assign(skeleton.parents.begin(), skeleton.parents.end());
  frame_seen_.assign(controller.database().frame_count(), 0);
  matched_dims_ = matched_trajectory_dims(controller.database(), offsets);
  r.leg_joints = ik_leg_joints(skeleton);
  r.foot_events.resize(r.agent_count);
  r.detail_agents = std::move(detail_agents);
  r.detail_rate_hz = 1.0f / dt;
  feet_now_.assign(r.agent_count, FootEvent{});
  for (FootEvent& now : feet_now_) now.state = 0xff;  // none yet: the first tick adds one
}

void CrowdRecorder::record_tick(std::uint64_t tick, std::span<const Match> collected,
                                std::span<const std::uint32_t> searched_before,
                                std::span<const SearchKind> kinds_before,
                                std::span<const std::uint32_t> frames_before, std::span<const glm::vec3> world) {
  const auto jumped = controller_.jumped();
  // The searches ran at the end of the previous tick.
  const float searched_at = float(tick) * dt_;
  for (std::size_t i = 0; i < collected.size() && i < searched_before.size(); ++i) {
    const std::uint32_t b = searched_before[i];
    SearchEvent event;
    event.time_s = searched_at;
    event.jumped = jumped[b] != 0;
    event.forced = kinds_before[b] == SearchKind::Forced;
    event.from_frame = std::int32_t(frames_before[b]);
    event.to_frame = collected[i].frame == kNoFrame ? -1 : std::int32_t(collected[i].frame);
    event.cost = std::isfinite(collected[i].cost) ? collected[i].cost : 0.0f;
    why_.applied(b, recording_.searches[b].size(), collected[i].frame);
    recording_.searches[b].push_back(event);
  }
  // Samples and foot events carry the time of the tick they were taken after.
  record_feet(float(tick) * dt_);
  if (tick % ticks_per_sample_ == 0) sample(world);
  sample_detail(world);
}

void CrowdRecorder::sample_detail(std::span<const glm::vec3> world) {
  Recording& r = recording_;
  const std::size_t joints = controller_.animation().joint_count();
  for (const std::uint32_t b : r.detail_agents) {
    for (std::size_t j = 0; j < joints; ++j) {
      const glm::vec3& p = world[std::size_t(b) * joints + j];
      r.detail_positions.insert(r.detail_positions.end(), {p.x, p.y, p.z});
    }
  }
  if (!r.detail_agents.empty()) ++r.detail_sample_count;
}

void CrowdRecorder::record_feet(float time_s) {
  const auto contacts = controller_.contacts();
  const auto locked = controller_.foot_locked();
  const auto anchors = controller_.foot_anchors();
  for (std::size_t b = 0; b < recording_.agent_count; ++b) {
    FootEvent next;
    next.time_s = time_s;
    next.state = std::uint8_t(((contacts[b] & kContactLeft) ? kFootPlantedLeft : 0) |
                              ((contacts[b] & kContactRight) ? kFootPlantedRight : 0));
    bool moved = false;
    for (std::size_t foot = 0; foot < 2; ++foot) {
      if (!locked[2 * b + foot]) continue;
      next.state |= std::uint8_t(foot == 0 ? kFootLockedLeft : kFootLockedRight);
      const glm::vec3& anchor = anchors[2 * b + foot];
      next.anchor[foot] = {anchor.x, anchor.y, anchor.z};
      const auto& was = feet_now_[b].anchor[foot];
      moved = moved || glm::length(anchor - glm::vec3(was[0], was[1], was[2])) > kAnchorMoveM;
    }
    if (next.state == feet_now_[b].state && !moved) continue;
    recording_.foot_events[b].push_back(next);
    feet_now_[b] = next;
  }
}

void CrowdRecorder::sample(std::span<const glm::vec3> world) {
  Recording& r = recording_;
  const std::size_t n = r.agent_count;
  const std::size_t points = r.trajectory_points();
  const auto roots = controller_.root_positions();
  const auto yaws = controller_.root_yaws();
  const auto frames = controller_.frames();
  const auto predicted = controller_.predicted_positions();
  const Database& db = controller_.database();
  const auto norm = db.normalization();
  for (std::size_t b = 0; b < n; ++b) {
    r.root_x.push_back(roots[b].x);
    r.root_z.push_back(roots[b].z);
    r.facing.push_back(yaws[b]);
    r.frame.push_back(std::int32_t(frames[b]));
    frame_seen_[frames[b]] = 1;
    const float c = std::cos(yaws[b]), s = std::sin(yaws[b]);
    for (std::size_t p = 0; p < points; ++p) {
      r.desired_x.push_back(predicted[b * points + p].x);
      r.desired_z.push_back(predicted[b * points + p].z);
      if (matched_dims_.empty()) continue;
      // The matched frame's future root, from its features (character space).
      const auto row = db.row(frames[b]);
      const std::uint32_t d = matched_dims_[p];
      const float x = row[d] * norm[d].scale + norm[d].offset;
      const float z = row[d + 1] * norm[d + 1].scale + norm[d + 1].offset;
      r.matched_x.push_back(roots[b].x + c * x + s * z);
      r.matched_z.push_back(roots[b].z - s * x + c * z);
    }
  }
  const std::size_t joints = controller_.animation().joint_count();
  for (std::size_t b = 0; b < n; ++b) {
    for (const std::int32_t j : r.leg_joints) {
      const glm::vec3& p = world[b * joints + std::size_t(j)];
      r.leg_positions.insert(r.leg_positions.end(), {p.x, p.y, p.z});
    }
  }
  ++r.sample_count;
}

Result<Recording> CrowdRecorder::finish(ThreadPool& pool) {
  Recording& r = recording_;
  const AnimationData& animation = controller_.animation();
  const std::size_t joints = animation.joint_count();
  for (std::uint32_t f = 0; f < frame_seen_.size(); ++f) {
    if (frame_seen_[f]) r.pose_frames.push_back(std::int32_t(f));
  }
  const std::size_t count = r.pose_frames.size();
  std::vector<glm::quat> rotations(count * joints);
  std::vector<glm::vec3> translations(count * joints), world(count * joints);
  for (std::size_t i = 0; i < count; ++i) {
    sample_pose(animation, std::uint32_t(r.pose_frames[i]), std::span(rotations).subspan(i * joints, joints),
                std::span(translations).subspan(i * joints, joints));
  }
  // Character space: every pose at the origin, facing +Z.
  const std::vector<glm::vec3> origins(count, glm::vec3(0.0f));
  const std::vector<float> zero_yaws(count, 0.0f);
  forward_kinematics_batch(animation.skeleton, rotations, translations, origins, zero_yaws, world, &pool);
  r.pose_positions.reserve(count * joints * 3);
  for (const glm::vec3& p : world) r.pose_positions.insert(r.pose_positions.end(), {p.x, p.y, p.z});
  MMVK_TRY(why_.finish(r, pool));
  return std::move(recording_);
}

}  // namespace mmvk::crowd
