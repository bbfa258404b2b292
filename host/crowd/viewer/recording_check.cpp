#include "viewer/recording_check.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace mmvk::crowd {
namespace {

Status size_error(const char* field, std::size_t actual, std::size_t expected, const std::string& shape) {
  return make_error("recording: " + std::string(field) + " has " + std::to_string(actual) +
                    " values, expected " + std::to_string(expected) + " (" + shape + ")");
}

Status check_size(const char* field, std::size_t actual, std::size_t expected, const std::string& shape) {
  return actual == expected ? Status{} : size_error(field, actual, expected, shape);
}

Status check_finite(const char* field, const std::vector<float>& values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return make_error("recording: " + std::string(field) + "[" + std::to_string(i) + "] is not finite");
    }
  }
  return {};
}

Status check_trajectories(const Recording& r) {
  float previous = 0.0f;
  for (std::size_t i = 0; i < r.trajectory_times_s.size(); ++i) {
    const float t = r.trajectory_times_s[i];
    if (!std::isfinite(t) || t <= previous) {
      return make_error("recording: trajectory_times_s[" + std::to_string(i) +
                        "] = " + std::to_string(t) + " is not positive and ascending");
    }
    previous = t;
  }
  const std::size_t points = r.agent_count * r.sample_count * r.trajectory_points();
  const std::string shape = "sample_count x agent_count x trajectory points";
  MMVK_TRY(check_size("desired_x", r.desired_x.size(), points, shape));
  MMVK_TRY(check_size("desired_z", r.desired_z.size(), points, shape));
  MMVK_TRY(check_finite("desired_x", r.desired_x));
  MMVK_TRY(check_finite("desired_z", r.desired_z));
  // The matched trajectory is optional: both empty, or both full.
  if (!r.matched_x.empty() || !r.matched_z.empty()) {
    MMVK_TRY(check_size("matched_x", r.matched_x.size(), points, shape + ", or empty"));
    MMVK_TRY(check_size("matched_z", r.matched_z.size(), points, shape + ", or empty"));
    MMVK_TRY(check_finite("matched_x", r.matched_x));
    MMVK_TRY(check_finite("matched_z", r.matched_z));
  }
  return {};
}

Status check_agents(const Recording& r) {
  MMVK_TRY(check_size("goals", r.goals.size(), r.agent_count, "one list per agent"));
  MMVK_TRY(check_size("searches", r.searches.size(), r.agent_count, "one list per agent"));
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    for (std::size_t g = 0; g < r.goals[a].size(); ++g) {
      if (!std::isfinite(r.goals[a][g].x) || !std::isfinite(r.goals[a][g].z)) {
        return make_error("recording: goals[" + std::to_string(a) + "][" + std::to_string(g) + "] is not finite");
      }
    }
    float previous = -INFINITY;
    for (std::size_t e = 0; e < r.searches[a].size(); ++e) {
      const SearchEvent& event = r.searches[a][e];
      const std::string where = "searches[" + std::to_string(a) + "][" + std::to_string(e) + "]";
      if (!std::isfinite(event.time_s) || event.time_s < 0.0f || event.time_s < previous) {
        return make_error("recording: " + where + ".time_s = " + std::to_string(event.time_s) +
                          " is negative, not finite or earlier than the event before");
      }
      if (std::isnan(event.cost)) return make_error("recording: " + where + ".cost is NaN");
      previous = event.time_s;
    }
  }
  return {};
}

Status check_skeleton(const Recording& r) {
  MMVK_TRY(check_size("joint_names", r.joint_names.size(), r.joint_count(), "one name per joint_parents entry"));
  for (std::size_t j = 0; j < r.joint_count(); ++j) {
    const int32_t parent = r.joint_parents[j];
    if (parent < -1 || parent >= static_cast<int32_t>(j)) {
      return make_error("recording: joint_parents[" + std::to_string(j) + "] = " + std::to_string(parent) +
                        " must be -1 or the index of an earlier joint");
    }
  }
  for (std::size_t p = 0; p < r.pose_frames.size(); ++p) {
    if (r.pose_frames[p] < 0 || (p > 0 && r.pose_frames[p] <= r.pose_frames[p - 1])) {
      return make_error("recording: pose_frames[" + std::to_string(p) + "] = " + std::to_string(r.pose_frames[p]) +
                        " is negative or not ascending and unique");
    }
  }
  MMVK_TRY(check_size("pose_positions", r.pose_positions.size(), r.pose_frames.size() * r.joint_count() * 3,
                      "pose_frames x joints x 3"));
  return check_finite("pose_positions", r.pose_positions);
}

Status check_feet(const Recording& r) {
  const std::size_t joints = r.joint_count();
  for (std::size_t i = 0; i < r.leg_joints.size(); ++i) {
    const int32_t j = r.leg_joints[i];
    if (j < 0 || std::size_t(j) >= joints || (i > 0 && j <= r.leg_joints[i - 1])) {
      return make_error("recording: leg_joints[" + std::to_string(i) + "] = " + std::to_string(j) +
                        " is not a joint index, or not ascending and unique");
    }
  }
  MMVK_TRY(check_size("leg_positions", r.leg_positions.size(),
                      r.sample_count * r.agent_count * r.leg_joints.size() * 3,
                      "sample_count x agent_count x leg_joints x 3"));
  MMVK_TRY(check_finite("leg_positions", r.leg_positions));
  if (r.foot_events.empty()) return {};
  MMVK_TRY(check_size("foot_events", r.foot_events.size(), r.agent_count, "one list per agent, or none"));
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    float previous = 0.0f;
    for (std::size_t e = 0; e < r.foot_events[a].size(); ++e) {
      const FootEvent& event = r.foot_events[a][e];
      const std::string where = "recording: foot_events[" + std::to_string(a) + "][" + std::to_string(e) + "]";
      if (!std::isfinite(event.time_s) || event.time_s < previous) {
        return make_error(where + ".time_s = " + std::to_string(event.time_s) +
                          " is negative, not finite or earlier than the event before");
      }
      if (event.state > 15) return make_error(where + ".state = " + std::to_string(event.state) + " is over 15");
      for (const auto& anchor : event.anchor) {
        for (float v : anchor) {
          if (!std::isfinite(v)) return make_error(where + ".anchor is not finite");
        }
      }
      previous = event.time_s;
    }
  }
  return {};
}

Status check_detail(const Recording& r) {
  for (std::size_t i = 0; i < r.detail_agents.size(); ++i) {
    const std::uint32_t a = r.detail_agents[i];
    if (a >= r.agent_count) {
      return make_error("recording: detail_agents[" + std::to_string(i) + "] = " + std::to_string(a) +
                        " is not below agent_count = " + std::to_string(r.agent_count));
    }
    if (i > 0 && a <= r.detail_agents[i - 1]) {
      return make_error("recording: detail_agents[" + std::to_string(i) + "] = " + std::to_string(a) +
                        " does not follow " + std::to_string(r.detail_agents[i - 1]) + " (ascending, unique)");
    }
  }
  if (!r.detail_agents.empty() && (!std::isfinite(r.detail_rate_hz) || r.detail_rate_hz <= 0.0f)) {
    return make_error("recording: detail_rate_hz = " + std::to_string(r.detail_rate_hz) + " must be positive");
  }
  MMVK_TRY(check_size("detail_positions", r.detail_positions.size(),
                      r.detail_sample_count * r.detail_agents.size() * r.joint_count() * 3,
                      "detail_sample_count x detail_agents x joints x 3"));
  return check_finite("detail_positions", r.detail_positions);
}

Status check_frame_why(const Recording& r, const Recording::FrameWhy& f, const std::string& where) {
  if (f.frame < 0) return {};
  if (f.clip >= r.clip_names.size()) {
    return make_error("recording: " + where + ".clip = " + std::to_string(f.clip) + " is not an index into clip_names (" +
                      std::to_string(r.clip_names.size()) + ")");
  }
  MMVK_TRY(check_size((where + ".weighted").c_str(), f.weighted.size(), r.channel_names.size(),
                      "one per channel_names entry"));
  for (float v : f.weighted) {
    if (!std::isfinite(v)) return make_error("recording: " + where + ".weighted is not finite");
  }
  if (f.exclusion >= std::max<std::size_t>(r.exclusion_names.size(), 1)) {
    return make_error("recording: " + where + ".exclusion = " + std::to_string(f.exclusion) +
                      " is not an index into exclusion_names (" + std::to_string(r.exclusion_names.size()) + ")");
  }
  if (!std::isfinite(f.cost) || !std::isfinite(f.bias) || !std::isfinite(f.multiplier)) {
    return make_error("recording: " + where + ": cost, bias or multiplier is not finite");
  }
  return {};
}

Status check_why(const Recording& r) {
  if (r.why.empty()) return {};
  MMVK_TRY(check_size("why", r.why.size(), r.agent_count, "one list per agent, or none"));
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    for (std::size_t e = 0; e < r.why[a].size(); ++e) {
      const Recording::SearchWhy& why = r.why[a][e];
      const std::string where = "why[" + std::to_string(a) + "][" + std::to_string(e) + "]";
      if (why.search >= r.searches[a].size() || (e > 0 && why.search <= r.why[a][e - 1].search)) {
        return make_error("recording: " + where + ".search = " + std::to_string(why.search) +
                          " is not an index into searches[" + std::to_string(a) + "], or not ascending");
      }
      MMVK_TRY(check_size((where + ".weights").c_str(), why.weights.size(), r.channel_names.size(),
                          "one per channel_names entry"));
      MMVK_TRY(check_frame_why(r, why.chosen, where + ".chosen"));
      MMVK_TRY(check_frame_why(r, why.continuing, where + ".continuing"));
    }
  }
  return {};
}

}  // namespace

Status validate_recording(const Recording& r) {
  if (!std::isfinite(r.sample_rate_hz) || r.sample_rate_hz <= 0.0f) {
    return make_error("recording: sample_rate_hz = " + std::to_string(r.sample_rate_hz) + " must be positive");
  }
  if (r.agent_count > 0 && r.sample_count == 0) {
    return make_error("recording: sample_count is 0 for " + std::to_string(r.agent_count) +
                      " agents (nothing was sampled)");
  }
  const std::size_t samples = r.agent_count * r.sample_count;
  const std::string shape = "sample_count x agent_count = " + std::to_string(r.sample_count) + " x " +
                            std::to_string(r.agent_count);
  MMVK_TRY(check_size("root_x", r.root_x.size(), samples, shape));
  MMVK_TRY(check_size("root_z", r.root_z.size(), samples, shape));
  MMVK_TRY(check_size("facing", r.facing.size(), samples, shape));
  MMVK_TRY(check_size("frame", r.frame.size(), samples, shape));
  MMVK_TRY(check_finite("root_x", r.root_x));
  MMVK_TRY(check_finite("root_z", r.root_z));
  MMVK_TRY(check_finite("facing", r.facing));
  MMVK_TRY(check_trajectories(r));
  MMVK_TRY(check_agents(r));
  MMVK_TRY(check_skeleton(r));
  MMVK_TRY(check_feet(r));
  MMVK_TRY(check_detail(r));
  return check_why(r);
}

}  // namespace mmvk::crowd
