// Everything `mmvk crowd` is asked to do, as the command line parsed it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace mmvk::crowd {

struct CrowdOptions {
  std::optional<std::filesystem::path> data;  // a shipped set's name, .mmdb, manifest or BVH folder; none = the default set
  std::optional<std::uint32_t> agents;        // none: kDefaultAgents, or the scenario's count
  double seconds = 10.0;                      // simulated time
  double rate_hz = 30.0;                      // simulation ticks per second
  double search_interval_s = 0.1;             // regular search period of each character
  std::string backend = "vulkan-brute";       // a backend registry name (mmvk/backends.hpp)
  std::optional<std::uint32_t> device;        // Vulkan device index; none = the best
  std::uint64_t seed = 1;
  std::optional<std::filesystem::path> scenario;
  std::optional<std::filesystem::path> summary;
  std::optional<std::filesystem::path> html;
  // Motion matching controls: none keeps the crowd's defaults (crowd_run.cpp).
  std::optional<float> continuing_bias;
  std::optional<float> continuing_multiplier;
  std::optional<std::uint32_t> exclusion_window;
  std::optional<float> correction_half_life;  // seconds, > 0
  std::vector<std::pair<std::string, float>> weights;  // schema channel name -> weight
  bool foot_ik = true;                                  // lock planted feet with two-bone IK
  // The displayed joint positions of the first trace_agents characters,
  // every tick (trace.hpp).
  std::optional<std::filesystem::path> trace;
  std::uint32_t trace_agents = 1;
  // Set by the command line, not by flags.
  std::filesystem::path executable;           // for the shipped data beside an installed binary
  std::filesystem::path cache_dir;            // empty: never cache
  bool progress = false;                      // draw the live progress line (stderr is a terminal)
};

}  // namespace mmvk::crowd
