// Every setting of a crowd, with its default, and the one check of them all.
// `mmvk crowd` (its flags, crowd_options.hpp), the stepped crowd
// (CrowdSession) and the Python module's mmvk.Crowd read this struct, so the
// three run with the same defaults and refuse the same values with the same
// bounds (crowd_limits.hpp), each naming the setting its own way
// ("--search-interval" or "search_interval").
//
// The motion-matching controls left unset take the data's tuned values (the
// "crowd" block of its manifest, data_settings.hpp), else the crowd's
// defaults (crowd_defaults.hpp).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mmvk/animation/crowd_controller.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/search/search.hpp"
#include "mmvk/common/status.hpp"
#include "setup/detail_agents.hpp"

namespace mmvk::crowd {

struct DataSettings;

struct CrowdSettings {
  std::optional<std::uint64_t> agents;  // 1 to kMaxAgents; none: kDefaultAgents, or the scenario's count
  double seconds = 10.0;                // simulated time of `mmvk crowd` (a session is stepped instead)
  double rate_hz = 30.0;                // simulation ticks per second
  double search_interval_s = 0.1;       // regular search period of each character
  std::string backend = "auto";         // a backend registry name (mmvk/search/backends.hpp) or "auto" (crowd_backend.hpp)
  std::optional<std::uint32_t> device;  // Vulkan device index; none = the best
  std::uint64_t seed = 1;               // the random scenario's
  // The random scenario's wait at each goal, seconds, 0 to kMaxGoalWaitS
  // (AgentPlan::wait_s); 0: leave at once. A scenario file sets its own.
  double wait_at_goals_s = 0.0;
  bool foot_ik = true;                  // lock planted feet with two-bone IK
  // Play rate and stride warping toward the commanded speed, and the root
  // correction held to the animation's own speed (ControllerParams'
  // defaults); false: every clip at its own speed, the correction bounded
  // by max_correction_speed alone (the controller before them).
  bool speed_from_animation = true;
  // Motion matching controls: none keeps the data's, else the crowd's defaults.
  std::optional<float> continuing_bias;
  std::optional<float> continuing_multiplier;  // >= 0
  std::optional<std::uint32_t> exclusion_window;
  std::optional<float> correction_half_life;  // seconds, > 0
  std::vector<std::pair<std::string, float>> weights;  // schema channel name -> weight, each >= 0
  // The characters a recording for the viewer keeps in detail (their whole
  // pose every tick, their searches explained); none: the first
  // kDefaultDetailAgents. Checked against the crowd once its size is known.
  std::optional<DetailAgents> detail_agents;
};

// How errors name a setting: as `mmvk crowd`'s flag ("--search-interval") or
// as mmvk.Crowd's keyword ("search_interval").
enum class SettingNames : std::uint8_t { Flags, Keywords };
// `flag` is the flag without its dashes ("search-interval").
std::string setting_name(SettingNames names, std::string_view flag);
// A value as the user gave it: the shortest text that reads back as the same
// double ("0.9999999", never "1"), so a bound is never shown as broken by a
// value that prints as inside it.
std::string exact_number_text(double value);
// The same for a float setting (its own shortest text: "3.4e+38").
std::string exact_number_text(float value);

// Everything that needs no database: the agent count, the times and the
// tick count, the controls' ranges. Runs before any allocation sized by them.
Status validate(const CrowdSettings& settings, SettingNames names);
// A whole number of characters, 1 to kMaxAgents (a caller's own integer
// type converted exactly, so a negative count is named as given).
Status check_agent_count(double agents, SettingNames names);
// round(seconds x rate) within [min_ticks, kMaxTicks] (crowd_limits.hpp);
// `seconds_name` names the seconds ("--seconds", "seconds").
Status check_tick_count(double seconds, double rate_hz, std::uint64_t min_ticks, const std::string& seconds_name,
                        SettingNames names);

// The controller's parameters: each setting given, else the data's, else the
// crowd's default.
ControllerParams controller_params(const CrowdSettings& settings, const DataSettings& data);
// The weights' channels on `database`, and the costs the weights and the
// controls allow checked against float overflow there; errors name the
// setting and its value. Before anything is allocated for the characters.
Status check_query_settings(const CrowdSettings& settings, const ControllerParams& params, const Database& database,
                            SettingNames names);
// The weights on every character's query options (after check_query_settings).
Status apply_query_settings(const CrowdSettings& settings, const Database& database, SettingNames names,
                            std::span<QueryParams> query_params);

}  // namespace mmvk::crowd
