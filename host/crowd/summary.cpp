#include "summary.hpp"

#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "mmvk/file_io.hpp"
#include "mmvk/hash.hpp"

namespace mmvk::crowd {

namespace {

// JSON has no NaN: a figure that could not be measured is null.
nlohmann::json number(double value) { return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr); }

}  // namespace

std::string summary_to_json(const CrowdSummary& s) {
  nlohmann::ordered_json j;
  j["agents"] = s.agents;
  j["ticks"] = s.ticks;
  j["seconds"] = s.seconds;
  j["rate_hz"] = s.rate_hz;
  j["search_interval_s"] = s.search_interval_s;
  j["seed"] = s.seed;
  j["scenario"] = s.scenario;
  j["database"] = s.database;
  j["database_frames"] = s.database_frames;
  j["walk_mps"] = number(s.walk_mps);
  j["run_mps"] = number(s.run_mps);
  j["backend"] = s.backend;
  j["device"] = s.device;
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
  j["foot_sliding_cm_s"] = number(s.foot_sliding_cm_s);
  j["foot_sliding_database_cm_s"] = number(s.foot_sliding_database_cm_s);
  j["transitions_per_agent_s"] = number(s.transitions_per_agent_s);
  j["goals_reached"] = s.goals_reached;
  // A string: a 64-bit value is not exact in every JSON reader's doubles.
  j["chosen_frames_hash"] = hash_hex(s.chosen_frames_hash);
  if (!s.html.empty()) {
    j["html"] = s.html;
    j["html_bytes"] = s.html_bytes;
  }
  // A scenario or database path may hold any bytes: invalid UTF-8 is
  // replaced (U+FFFD) instead of thrown as an exception.
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

Status write_summary(const CrowdSummary& summary, const std::filesystem::path& path) {
  if (Status written = write_file_atomically(path, summary_to_json(summary)); !written) {
    return make_error("--summary: " + written.message());
  }
  return {};
}

}  // namespace mmvk::crowd
