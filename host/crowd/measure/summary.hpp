// The --summary JSON of a crowd run: what ran, how fast and how well.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "measure/command_meter.hpp"
#include "mmvk/common/status.hpp"
#include "measure/motion_meter.hpp"

namespace mmvk::crowd {

struct CrowdSummary {
  // What ran.
  std::uint64_t agents = 0;
  std::uint64_t ticks = 0;
  double seconds = 0.0;            // simulated
  double rate_hz = 0.0;
  double search_interval_s = 0.0;
  double correction_half_life_s = 0.0;  // the root correction's half-life it ran with (the set's or the flag's)
  std::uint64_t seed = 0;
  std::string scenario;            // file or "seed N"
  std::string database;            // the .mmdb or source folder
  std::uint64_t database_frames = 0;
  double walk_mps = 0.0;           // measured in the database
  double run_mps = 0.0;            // NaN (null in the JSON) when the data has no run
  std::uint64_t runners = 0;       // characters that prefer to run
  std::string backend;
  std::string device;              // "cpu" for CPU backends
  std::string backend_choice;      // why --backend auto picked `backend`; empty: it was named
  // How fast.
  std::uint64_t searches = 0;      // queries searched
  std::uint64_t forced_searches = 0;
  std::uint64_t no_candidate = 0;  // queries that found no frame
  double queries_per_tick = 0.0;
  double search_ms_p50 = 0.0, search_ms_p99 = 0.0;  // per tick: the batched search (submit to results)
  double tick_ms_p50 = 0.0, tick_ms_p99 = 0.0;      // per tick: steering + controller + search
  double wall_seconds = 0.0;
  double realtime_factor = 0.0;    // simulated seconds per wall second
  // How well.
  double trajectory_error_m_1s = 0.0;
  bool foot_ik = true;             // --foot-ik
  bool speed_from_animation = true;  // --speed-from-animation
  MotionFigures motion;            // the crowd's displayed pose (motion_meter.hpp)
  MotionFigures clips;             // the same measures on the database's own clips (clip_quality.hpp)
  CommandFigures command;          // glide and errors against the command (command_meter.hpp)
  std::array<float, 2> planted_height_m{0.0f, 0.0f};  // the toes' height when planted, from the clips
  double transitions_per_agent_s = 0.0;
  std::uint64_t goals_reached = 0;
  std::uint64_t chosen_frames_hash = 0;
  // What the data cannot do for this run: no run, no idle, the speeds it
  // lacks (data_notes.hpp); `mmvk crowd` prints them last.
  std::vector<std::string> notes;
  // The viewer and the trace, when written.
  std::string html;
  std::uint64_t html_bytes = 0;
  std::string trace;
};

std::string summary_to_json(const CrowdSummary& summary);
// The motion figures for the user, three lines ending in '\\n', each figure
// with the clips' beside it.
std::string describe_motion(const CrowdSummary& summary);
Status write_summary(const CrowdSummary& summary, const std::filesystem::path& path);

}  // namespace mmvk::crowd
