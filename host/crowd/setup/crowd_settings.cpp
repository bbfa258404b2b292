#include "setup/crowd_settings.hpp"

#include <charconv>
#include <cmath>

#include "setup/crowd_defaults.hpp"
#include "setup/crowd_limits.hpp"
#include "setup/data_settings.hpp"
#include "mmvk/common/number_text.hpp"

namespace mmvk::crowd {

std::string setting_name(SettingNames names, std::string_view flag) {
  std::string name(flag);
  if (names == SettingNames::Flags) return "--" + name;
  for (char& c : name) c = c == '-' ? '_' : c;
  return name;
}

std::string exact_number_text(double value) {
  char text[64];
  const auto [end, error] = std::to_chars(text, text + sizeof(text), value);
  return error == std::errc{} ? std::string(text, end) : number_text(value);
}

std::string exact_number_text(float value) {
  char text[64];
  const auto [end, error] = std::to_chars(text, text + sizeof(text), value);
  return error == std::errc{} ? std::string(text, end) : number_text(value);
}

namespace {

// "--rate 0.5: expected 1 to 1000 ticks per second": the value as given, the bounds as documented.
Error out_of_range(SettingNames names, std::string_view flag, double value, double min, double max,
                   const std::string& unit) {
  return make_error(setting_name(names, flag) + " " + exact_number_text(value) + ": expected " + number_text(min) +
                    " to " + number_text(max) + unit);
}

bool within(double value, double min, double max) { return std::isfinite(value) && value >= min && value <= max; }

Status check_controls(const CrowdSettings& s, SettingNames names) {
  if (s.continuing_bias && !std::isfinite(*s.continuing_bias)) {
    return make_error(setting_name(names, "continuing-bias") + " must be finite");
  }
  if (s.continuing_multiplier && !(std::isfinite(*s.continuing_multiplier) && *s.continuing_multiplier >= 0.0f)) {
    return make_error(setting_name(names, "continuing-multiplier") + " " + exact_number_text(*s.continuing_multiplier) +
                      ": expected a finite number >= 0");
  }
  if (s.correction_half_life && !(std::isfinite(*s.correction_half_life) && *s.correction_half_life > 0.0f)) {
    return make_error(setting_name(names, "correction-half-life") + " " + exact_number_text(*s.correction_half_life) +
                      ": expected a positive number of seconds");
  }
  for (const auto& [channel, weight] : s.weights) {
    if (!(std::isfinite(weight) && weight >= 0.0f)) {
      return make_error(setting_name(names, "weights") + " " + channel + "=" + exact_number_text(weight) +
                        ": expected a finite weight >= 0");
    }
  }
  return {};
}

}  // namespace

Status check_tick_count(double seconds, double rate_hz, std::uint64_t min_ticks, const std::string& seconds_name,
                        SettingNames names) {
  const std::string given = seconds_name + " " + exact_number_text(seconds) + " at " + setting_name(names, "rate") +
                            " " + exact_number_text(rate_hz);
  if (!std::isfinite(seconds) || seconds < 0.0) {
    return make_error(seconds_name + " " + exact_number_text(seconds) + ": expected a finite number of seconds >= 0");
  }
  if (seconds * rate_hz > double(kMaxTicks) + 0.5) {
    return make_error(given + ": over " + std::to_string(kMaxTicks) + " ticks (seconds x rate)");
  }
  if (std::uint64_t(std::llround(seconds * rate_hz)) < min_ticks) {
    return make_error(given + " Hz is 0 ticks; simulate at least one tick (1 / rate seconds)");
  }
  return {};
}

Status check_agent_count(double agents, SettingNames names) {
  const bool whole = agents == std::floor(agents) && std::fabs(agents) < 9.0e18;
  if (whole && agents >= 1.0 && agents <= double(kMaxAgents)) return {};
  // A count as it was typed: "10000000", not "1e+07".
  const std::string given = whole ? std::to_string(static_cast<long long>(agents)) : exact_number_text(agents);
  return make_error(setting_name(names, "agents") + " " + given + ": expected 1 to " +
                    std::to_string(kMaxAgents) + " characters (the search's batch limit)");
}

Status validate(const CrowdSettings& s, SettingNames names) {
  if (s.agents) MMVK_TRY(check_agent_count(double(*s.agents), names));
  if (!within(s.rate_hz, kMinRateHz, kMaxRateHz)) {
    return out_of_range(names, "rate", s.rate_hz, kMinRateHz, kMaxRateHz,
                        " ticks per second (a tick of at most 1 s and at least 1 ms)");
  }
  if (!within(s.search_interval_s, kMinSearchIntervalS, kMaxSearchIntervalS)) {
    return out_of_range(names, "search-interval", s.search_interval_s, kMinSearchIntervalS, kMaxSearchIntervalS,
                        " seconds");
  }
  if (!within(s.wait_at_goals_s, 0.0, kMaxGoalWaitS)) {
    return out_of_range(names, "wait-at-goals", s.wait_at_goals_s, 0.0, kMaxGoalWaitS, " seconds");
  }
  MMVK_TRY(check_tick_count(s.seconds, s.rate_hz, 1, setting_name(names, "seconds"), names));
  return check_controls(s, names);
}

ControllerParams controller_params(const CrowdSettings& s, const DataSettings& data) {
  ControllerParams params;
  params.search_interval = float(s.search_interval_s);
  params.continuing_bias = s.continuing_bias.value_or(data.continuing_bias.value_or(kContinuingBias));
  params.correction_half_life =
      s.correction_half_life.value_or(data.correction_half_life.value_or(kCorrectionHalfLife));
  params.continuing_multiplier =
      s.continuing_multiplier.value_or(data.continuing_multiplier.value_or(params.continuing_multiplier));
  params.exclusion_window = s.exclusion_window.value_or(data.exclusion_window.value_or(params.exclusion_window));
  params.foot_ik.enabled = s.foot_ik;
  if (!s.speed_from_animation) {
    params.min_play_rate = params.max_play_rate = params.min_stride_scale = params.max_stride_scale = 1.0f;
    // A floor at the cap leaves the cap as the only bound.
    params.min_correction_speed = params.max_correction_speed;
  }
  return params;
}

namespace {

// The error of a setting whose value alone makes the costs overflow.
Error overflows(const std::string& what) {
  return make_error(what + ": the search's costs could overflow float on this database (they are sums of squared "
                    "normalized features, usually within a few hundred); lower it");
}

// Each control alone, then all of them together, so that the error names
// the one at fault.
Status check_cost_overflow(const CrowdSettings& s, const ControllerParams& params, const QueryParams& weighted,
                           const Database& database, SettingNames names) {
  QueryParams bias;
  bias.continuing_bias = params.continuing_bias;
  if (!params_fit_cost_bound(database, bias)) {
    return overflows(setting_name(names, "continuing-bias") + " " + exact_number_text(params.continuing_bias));
  }
  QueryParams multiplier;
  multiplier.continuing_multiplier = params.continuing_multiplier;
  if (!params_fit_cost_bound(database, multiplier)) {
    return overflows(setting_name(names, "continuing-multiplier") + " " +
                     exact_number_text(params.continuing_multiplier));
  }
  for (const auto& [channel, weight] : s.weights) {
    QueryParams one;
    (void)set_channel_weight(database.schema(), one, channel, weight);
    if (!params_fit_cost_bound(database, one)) {
      return overflows(setting_name(names, "weights") + " " + channel + "=" + exact_number_text(weight));
    }
  }
  QueryParams all = weighted;
  all.continuing_bias = params.continuing_bias;
  all.continuing_multiplier = params.continuing_multiplier;
  if (!params_fit_cost_bound(database, all)) {
    return overflows("the continuing bias, continuing multiplier and " + setting_name(names, "weights") +
                     " together");
  }
  return {};
}

// --weights on one query's options; errors name --weights.
Result<QueryParams> weighted_params(const CrowdSettings& s, const Database& database, SettingNames names) {
  QueryParams weighted;
  for (const auto& [channel, weight] : s.weights) {
    if (Status set = set_channel_weight(database.schema(), weighted, channel, weight); !set) {
      return make_error(setting_name(names, "weights") + ": " + set.message());
    }
  }
  return weighted;
}

}  // namespace

Status check_query_settings(const CrowdSettings& s, const ControllerParams& params, const Database& database,
                            SettingNames names) {
  MMVK_ASSIGN_OR_RETURN(const QueryParams weighted, weighted_params(s, database, names));
  return check_cost_overflow(s, params, weighted, database, names);
}

Status apply_query_settings(const CrowdSettings& s, const Database& database, SettingNames names,
                            std::span<QueryParams> query_params) {
  if (s.weights.empty()) return {};
  MMVK_ASSIGN_OR_RETURN(const QueryParams weighted, weighted_params(s, database, names));
  for (QueryParams& p : query_params) p.channel_weights = weighted.channel_weights;
  return {};
}

}  // namespace mmvk::crowd
