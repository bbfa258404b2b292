#include "measure/summary.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "mmvk/common/file_io.hpp"
#include "mmvk/common/hash.hpp"

namespace mmvk::crowd {

namespace {

// JSON has no NaN: a figure that could not be measured is null.
nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr); }

// The figures both the crowd and the clips have, under the same keys.
void add_motion(nlohmann::ordered_json& j, const MotionFigures& m) {
  j["foot_sliding_cm_s"] = number(m.foot_sliding_cm_s);
  j["knee_speed_p99_deg_s"] = number(m.knee_speed_p99_deg_s);
  j["foot_height_in_contact_cm"] = {{"mean", number(m.foot_height_in_contact_cm_mean)},
                                    {"p95", number(m.foot_height_in_contact_cm_p95)}};
}

// The glide and the errors against the command (command_meter.hpp).
void add_command(nlohmann::ordered_json& j, const CommandFigures& c) {
  j["glide_cm_s"] = {{"mean", number(c.glide_cm_s_mean)},
                     {"median", number(c.glide_cm_s_median)},
                     {"p95", number(c.glide_cm_s_p95)}};
  j["glide_share_of_travel"] = number(c.glide_share_of_travel);
  j["animation_share_of_travel"] = number(c.animation_share_of_travel);
  j["steady_moving_fraction"] = number(c.steady_moving_fraction);
  j["steady_standing_fraction"] = number(c.steady_standing_fraction);
  j["standing_still_share"] = number(c.standing_still_share);
  j["played_speed_error"] = {{"median", number(c.played_speed_error_median)},
                             {"p95", number(c.played_speed_error_p95)}};
  j["shown_speed_error"] = {{"median", number(c.shown_speed_error_median)}, {"p95", number(c.shown_speed_error_p95)}};
  j["heading_error_deg"] = {{"median", number(c.heading_error_deg_median)}, {"p95", number(c.heading_error_deg_p95)}};
}

}  // namespace

std::string summary_to_json(const CrowdSummary& s) {
  nlohmann::ordered_json j;
  j["agents"] = s.agents;
  j["ticks"] = s.ticks;
  j["seconds"] = s.seconds;
  j["rate_hz"] = s.rate_hz;
  j["search_interval_s"] = s.search_interval_s;
  j["correction_half_life_s"] = s.correction_half_life_s;
  j["seed"] = s.seed;
  j["scenario"] = s.scenario;
  j["database"] = s.database;
  j["database_frames"] = s.database_frames;
  j["walk_mps"] = number(s.walk_mps);
  j["run_mps"] = number(s.run_mps);
  j["runners"] = s.runners;
  j["backend"] = s.backend;
  j["device"] = s.device;
  j["backend_choice"] = s.backend_choice.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.backend_choice);
  j["searches"] = s.searches;
  j["forced_searches"] = s.forced_searches;
  j["no_candidate"] = s.no_candidate;
  j["queries_per_tick"] = number(s.queries_per_tick);
  j["search_ms_p50"] = number(s.search_ms_p50);
  j["search_ms_p99"] = number(s.search_ms_p99);
  j["tick_ms_p50"] = number(s.tick_ms_p50);
  j["tick_ms_p99"] = number(s.tick_ms_p99);
  j["wall_seconds"] = number(s.wall_seconds);
  j["realtime_factor"] = number(s.realtime_factor);
  j["trajectory_error_m_1s"] = number(s.trajectory_error_m_1s);
  j["foot_ik"] = s.foot_ik;
  j["speed_from_animation"] = s.speed_from_animation;
  add_motion(j, s.motion);
  j["foot_sliding_before_ik_cm_s"] = number(s.motion.foot_sliding_before_ik_cm_s);
  j["foot_sliding_database_cm_s"] = number(s.clips.foot_sliding_cm_s);
  j["foot_lock_fraction"] = number(s.motion.foot_lock_fraction);
  j["ik_reach_clamped_fraction"] = number(s.motion.ik_reach_clamped_fraction);
  j["pose_acceleration_p99_m_s2"] = {{"at_jumps", number(s.motion.pose_acceleration_p99_at_jumps_m_s2)},
                                     {"elsewhere", number(s.motion.pose_acceleration_p99_m_s2)}};
  nlohmann::ordered_json clips;
  add_motion(clips, s.clips);
  clips["pose_acceleration_p99_m_s2"] = number(s.clips.pose_acceleration_p99_m_s2);
  clips["planted_height_m"] = {number(s.planted_height_m[0]), number(s.planted_height_m[1])};
  j["clips"] = clips;
  add_command(j, s.command);
  j["transitions_per_agent_s"] = number(s.transitions_per_agent_s);
  j["goals_reached"] = s.goals_reached;
  // A string: a 64-bit value is not exact in every JSON reader's doubles.
  j["chosen_frames_hash"] = hash_hex(s.chosen_frames_hash);
  j["notes"] = s.notes;
  if (!s.html.empty()) {
    j["html"] = s.html;
    j["html_bytes"] = s.html_bytes;
  }
  if (!s.trace.empty()) j["trace"] = s.trace;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

std::string describe_motion(const CrowdSummary& s) {
  const MotionFigures& m = s.motion;
  const MotionFigures& c = s.clips;
  const CommandFigures& g = s.command;
  char text[1280];
  std::snprintf(text, sizeof(text),
                "mmvk crowd: feet%s: sliding in contact %.2f cm/s (before IK %.2f, the clips %.2f), "
                "%.1f%% of planted foot-ticks locked, %.2f%% of foot-ticks reach-clamped, toe height in contact "
                "%.2f / %.2f cm mean / p95 (the clips %.2f / %.2f)\n"
                "mmvk crowd: knees %.0f deg/s p99 (the clips %.0f); pose acceleration p99 %.1f m/s^2 at jumps, "
                "%.1f elsewhere (the clips %.1f)\n"
                "mmvk crowd: glide (the root correction) %.1f / %.1f / %.1f cm/s mean / median / p95, %.1f%% of the "
                "travel (the animation %.1f%%); held commands: played speed off by %.1f%% (p95 %.1f%%), shown "
                "%.1f%% (p95 %.1f%%), heading %.1f deg (p95 %.1f)\n",
                s.foot_ik ? "" : " (foot IK off)", m.foot_sliding_cm_s, m.foot_sliding_before_ik_cm_s,
                c.foot_sliding_cm_s, 100.0 * m.foot_lock_fraction, 100.0 * m.ik_reach_clamped_fraction,
                m.foot_height_in_contact_cm_mean, m.foot_height_in_contact_cm_p95, c.foot_height_in_contact_cm_mean,
                c.foot_height_in_contact_cm_p95, m.knee_speed_p99_deg_s, c.knee_speed_p99_deg_s,
                m.pose_acceleration_p99_at_jumps_m_s2, m.pose_acceleration_p99_m_s2, c.pose_acceleration_p99_m_s2,
                g.glide_cm_s_mean, g.glide_cm_s_median, g.glide_cm_s_p95, 100.0 * g.glide_share_of_travel,
                100.0 * g.animation_share_of_travel, 100.0 * g.played_speed_error_median,
                100.0 * g.played_speed_error_p95, 100.0 * g.shown_speed_error_median, 100.0 * g.shown_speed_error_p95,
                g.heading_error_deg_median, g.heading_error_deg_p95);
  std::string out = text;
  if (std::isfinite(g.standing_still_share)) {
    std::snprintf(text, sizeof(text),
                  "mmvk crowd: told to stand: %.1f%% of the steady standing ticks still (root and toes under 5 "
                  "cm/s)\n",
                  100.0 * g.standing_still_share);
    out += text;
  }
  return out;
}

Status write_summary(const CrowdSummary& summary, const std::filesystem::path& path) {
  if (Status written = write_file_atomically(path, summary_to_json(summary)); !written) {
    return make_error("--summary: " + written.message());
  }
  return {};
}

}  // namespace mmvk::crowd
