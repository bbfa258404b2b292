#include "steering/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "setup/crowd_limits.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/input_text.hpp"
#include "mmvk/common/json_check.hpp"
#include "mmvk/common/number_text.hpp"
#include "steering/random.hpp"

namespace mmvk::crowd {

namespace {

using Json = nlohmann::json;

Status check_fields(const Json& object, const std::string& where, const std::set<std::string>& known) {
  for (const auto& item : object.items()) {
    if (!known.count(item.key())) return make_error(where + printable_text(item.key()) + ": unknown field");
  }
  return {};
}

Result<float> read_number(const Json& value, const std::string& where) {
  if (!value.is_number()) return make_error(where + ": expected a number");
  const double number = value.get<double>();
  // Positions beyond a few hundred kilometres would break float steering.
  if (!std::isfinite(number) || std::abs(number) > 1.0e6) return make_error(where + ": not a finite number below 1e6");
  return static_cast<float>(number);
}

Result<std::array<float, 2>> read_point(const Json& value, const std::string& where) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number()) {
    return make_error(where + ": expected [x, z] numbers");
  }
  std::array<float, 2> point{};
  for (std::size_t i = 0; i < 2; ++i) {
    Result<float> number = read_number(value[i], where + "[" + std::to_string(i) + "]");
    if (!number) return number.error();
    point[i] = *number;
  }
  return point;
}

Result<std::vector<std::string>> read_tags(const Json& value, const std::string& where) {
  if (!value.is_array()) return make_error(where + ": expected an array of tag names");
  std::vector<std::string> tags;
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (!value[i].is_string() || value[i].get<std::string>().empty()) {
      return make_error(where + "[" + std::to_string(i) + "]: expected a tag name");
    }
    tags.push_back(value[i].get<std::string>());
  }
  return tags;
}

Result<SpeedPreference> read_speed(const Json& value, const std::string& where) {
  if (value.is_string()) {
    const std::string name = value.get<std::string>();
    if (name == "walk") return SpeedPreference{Gait::Walk, 1.0f};
    if (name == "run") return SpeedPreference{Gait::Run, 1.0f};
    return make_error(where + ": expected \"walk\", \"run\" or metres/second, got " + quoted_text(name));
  }
  Result<float> metres = read_number(value, where);
  if (!metres) return make_error(where + ": expected \"walk\", \"run\" or metres/second");
  if (!(*metres > 0.0f)) return make_error(where + ": a speed must be > 0 metres/second");
  return SpeedPreference{Gait::Metres, *metres};
}

// A wait at a goal: seconds, 0 to kMaxGoalWaitS. The reader already
// refuses 1e999; isfinite keeps the bound honest without relying on it.
Result<float> read_wait(const Json& value, const std::string& where) {
  const std::string expected = ": expected seconds from 0 to " + number_text(kMaxGoalWaitS);
  if (!value.is_number()) return make_error(where + expected);
  const double seconds = value.get<double>();
  if (!std::isfinite(seconds) || seconds < 0.0 || seconds > kMaxGoalWaitS) {
    return make_error(where + expected + ", got " + number_text(seconds));
  }
  return static_cast<float>(seconds);
}

// `wait_s`: the scenario's default wait, for an agent without its own.
Result<AgentPlan> parse_agent(const Json& object, const std::string& where, float wait_s) {
  if (!object.is_object()) return make_error(where + ": expected an object");
  MMVK_TRY(check_fields(object, where + ".", {"start", "goals", "speed", "require_tags", "exclude_tags", "wait_s"}));
  AgentPlan plan;
  plan.wait_s = wait_s;
  if (!object.contains("start")) return make_error(where + ".start: missing");
  MMVK_ASSIGN_OR_RETURN(plan.start, read_point(object["start"], where + ".start"));
  if (!object.contains("goals")) return make_error(where + ".goals: missing");
  const Json& goals = object["goals"];
  if (!goals.is_array() || goals.empty()) return make_error(where + ".goals: expected a non-empty array of [x, z]");
  for (std::size_t g = 0; g < goals.size(); ++g) {
    MMVK_ASSIGN_OR_RETURN(auto point, read_point(goals[g], where + ".goals[" + std::to_string(g) + "]"));
    plan.goals.push_back(point);
  }
  if (object.contains("speed")) {
    MMVK_ASSIGN_OR_RETURN(plan.speed, read_speed(object["speed"], where + ".speed"));
  }
  if (object.contains("require_tags")) {
    MMVK_ASSIGN_OR_RETURN(plan.require_tags, read_tags(object["require_tags"], where + ".require_tags"));
  }
  if (object.contains("exclude_tags")) {
    MMVK_ASSIGN_OR_RETURN(plan.exclude_tags, read_tags(object["exclude_tags"], where + ".exclude_tags"));
  }
  if (object.contains("wait_s")) {
    MMVK_ASSIGN_OR_RETURN(plan.wait_s, read_wait(object["wait_s"], where + ".wait_s"));
  }
  return plan;
}

}  // namespace

Scenario make_random_scenario(const RandomScenarioOptions& options) {
  Scenario scenario;
  scenario.source = "seed " + std::to_string(options.seed);
  scenario.world_size_m = std::max(10.0f, std::sqrt(float(options.agents) * options.area_per_agent_m2));
  const float half = 0.5f * scenario.world_size_m;
  Random random(options.seed);
  scenario.agents.resize(options.agents);
  for (AgentPlan& plan : scenario.agents) {
    plan.start = {random.uniform(-half, half), random.uniform(-half, half)};
    // Each goal a short walk from the last, so that characters turn every
    // few seconds instead of crossing the whole plane in a straight line.
    plan.goals.resize(std::max<std::uint32_t>(1, options.goals_per_agent));
    std::array<float, 2> from = plan.start;
    for (auto& goal : plan.goals) {
      const float angle = random.uniform(0.0f, 6.2831853f);
      const float distance = random.uniform(options.min_goal_distance_m, options.max_goal_distance_m);
      goal = {std::clamp(from[0] + distance * std::cos(angle), -half, half),
              std::clamp(from[1] + distance * std::sin(angle), -half, half)};
      from = goal;
    }
    // Walkers spread around the measured walk speed, runners just under the
    // run speed: a crowd is not a marching band.
    if (random.uniform(0.0f, 1.0f) < options.run_fraction) {
      plan.speed = {Gait::Run, random.uniform(0.85f, 1.0f)};
    } else {
      plan.speed = {Gait::Walk, random.uniform(0.8f, 1.1f)};
    }
    // Not drawn: the same seed gives the same goals and speeds at any wait.
    plan.wait_s = options.wait_s;
  }
  return scenario;
}

Result<Scenario> parse_scenario_json(std::string_view json_text, std::string_view source) {
  const std::string name(source.empty() ? std::string_view("scenario") : source);
  // Duplicate keys, NUL bytes and trailing bytes are errors, as in every
  // mmvk JSON input.
  MMVK_TRY(check_json_text(json_text, name));
  const Json root = Json::parse(json_text, nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) return make_error(name + ": not valid JSON");
  if (!root.is_object()) return make_error(name + ": expected a JSON object with \"agents\"");
  MMVK_TRY(check_fields(root, name + ": ", {"world_size_m", "wait_s", "agents"}));
  Scenario scenario;
  scenario.source = name;
  if (!root.contains("agents")) return make_error(name + ": agents: missing");
  const Json& agents = root["agents"];
  if (!agents.is_array() || agents.empty()) return make_error(name + ": agents: expected a non-empty array");
  if (agents.size() > kMaxAgents) {
    return make_error(name + ": agents: " + std::to_string(agents.size()) + " agents, over the limit of " +
                      std::to_string(kMaxAgents));
  }
  float wait_s = 0.0f;
  if (root.contains("wait_s")) {
    MMVK_ASSIGN_OR_RETURN(wait_s, read_wait(root["wait_s"], name + ": wait_s"));
  }
  float extent = 0.0f;
  for (std::size_t a = 0; a < agents.size(); ++a) {
    MMVK_ASSIGN_OR_RETURN(AgentPlan plan,
                          parse_agent(agents[a], name + ": agents[" + std::to_string(a) + "]", wait_s));
    extent = std::max({extent, std::abs(plan.start[0]), std::abs(plan.start[1])});
    for (const auto& goal : plan.goals) extent = std::max({extent, std::abs(goal[0]), std::abs(goal[1])});
    scenario.agents.push_back(std::move(plan));
  }
  scenario.world_size_m = 2.0f * extent + 4.0f;
  if (root.contains("world_size_m")) {
    MMVK_ASSIGN_OR_RETURN(scenario.world_size_m, read_number(root["world_size_m"], name + ": world_size_m"));
    if (!(scenario.world_size_m > 0.0f)) return make_error(name + ": world_size_m: must be > 0");
  }
  return scenario;
}

Result<Scenario> load_scenario(const std::filesystem::path& path) {
  // A regular file of at most kMaxJsonBytes: --scenario /dev/zero or a FIFO
  // fails at once.
  Result<std::string> text = read_file(path, ReadOptions{kMaxJsonBytes, false});
  if (!text) return make_error("--scenario: " + text.message());
  return parse_scenario_json(*text, path.string());
}

}  // namespace mmvk::crowd
