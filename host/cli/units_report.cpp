#include "units_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "steering/gait_speeds.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/animation/pose_batch.hpp"

namespace mmvk::cli {

namespace {

// The import's known units, by name (guess_metres_per_unit's candidates).
const char* unit_name(float metres_per_unit) {
  const struct {
    float value;
    const char* name;
  } kNames[] = {{0.01f, "centimetres"}, {0.0254f, "inches"}, {0.05644f, "CMU ASF units"}, {1.0f, "metres"}};
  for (const auto& unit : kNames) {
    if (std::abs(metres_per_unit - unit.value) <= 1e-3f * unit.value) return unit.name;
  }
  return nullptr;
}

struct UnitCount {
  float value;        // 0 = not recorded
  std::size_t clips;
};

// The distinct metres-per-unit values over the clips, in order of first use.
std::vector<UnitCount> unit_counts(const Database& database) {
  std::vector<UnitCount> counts;
  for (const Clip& clip : database.clips()) {
    auto it = std::find_if(counts.begin(), counts.end(),
                           [&](const UnitCount& c) { return c.value == clip.metres_per_unit; });
    if (it == counts.end()) {
      counts.push_back({clip.metres_per_unit, 1});
    } else {
      ++it->clips;
    }
  }
  return counts;
}

// What the database's poses say about the import, over its frames (at most
// kFrames of them, evenly spread).
//  - height: the skeleton's standing height, metres: the highest joint above
//    the lowest, taken at the 90th percentile, so that crouches and bent
//    knees do not count and a stray frame does not either. Measured on the
//    animation rather than the rest pose, which is not upright on every
//    skeleton (Bandai's bones lie along local X). Joints only: the End
//    Sites' tips are not stored, so the highest joint is the head joint,
//    below the top of the head.
//  - body_up: the mean y of the unit feet-to-head vector, the axis the
//    import stood the character along (1 = +Y, as the build's import check
//    wants: import_check.hpp); none when the roles do not resolve.
struct PoseFigures {
  double height = 0.0;
  std::optional<double> body_up;
};

std::optional<PoseFigures> pose_figures(const Database& database) {
  constexpr std::uint32_t kFrames = 4096;
  const AnimationData* a = database.animation();
  if (a == nullptr || a->joint_count() == 0 || a->frame_count == 0) return std::nullopt;
  const std::size_t joints = a->joint_count();
  const std::uint32_t count = std::min(a->frame_count, kFrames);
  std::vector<glm::quat> rotations(count * joints);
  std::vector<glm::vec3> translations(count * joints), world(count * joints), roots(count, glm::vec3(0.0f));
  const std::vector<float> yaws(count, 0.0f);
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto frame = std::uint32_t(std::uint64_t{i} * a->frame_count / count);
    sample_pose(*a, frame, std::span(rotations).subspan(i * joints, joints),
                std::span(translations).subspan(i * joints, joints));
  }
  forward_kinematics_batch(a->skeleton, rotations, translations, roots, yaws, world);
  const Result<int> head = find_bone(a->skeleton, "@head"), left = find_bone(a->skeleton, "@left_foot"),
                    right = find_bone(a->skeleton, "@right_foot");
  const bool human = head.ok() && left.ok() && right.ok();
  std::vector<double> heights(count);
  double up = 0.0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto pose = std::span(world).subspan(i * joints, joints);
    const auto [low, high] = std::minmax_element(pose.begin(), pose.end(),
                                                 [](const glm::vec3& p, const glm::vec3& q) { return p.y < q.y; });
    heights[i] = double(high->y - low->y);
    if (!human) continue;
    const glm::vec3 body = pose[std::size_t(*head)] - 0.5f * (pose[std::size_t(*left)] + pose[std::size_t(*right)]);
    up += glm::length(body) > 0.0f ? double(body.y / glm::length(body)) : 0.0;
  }
  const auto at = heights.begin() + std::ptrdiff_t(0.9 * double(count - 1));
  std::nth_element(heights.begin(), at, heights.end());
  PoseFigures out;
  out.height = *at;
  if (human) out.body_up = up / count;
  return out;
}

struct SourceCount {
  std::string from;  // empty = not recorded
  std::size_t clips;
};

// The distinct values of a clip's record of the import (units_from or
// axes_from), in order of first use.
std::vector<SourceCount> source_counts(const Database& database, std::string Clip::*field) {
  std::vector<SourceCount> counts;
  for (const Clip& clip : database.clips()) {
    auto it = std::find_if(counts.begin(), counts.end(), [&](const SourceCount& c) { return c.from == clip.*field; });
    if (it == counts.end()) {
      counts.push_back({clip.*field, 1});
    } else {
      ++it->clips;
    }
  }
  return counts;
}

// "the manifest's import.up_axis, 12 clips; ..." for `mmvk inspect`.
std::string sources_text(const Database& database, std::string Clip::*field) {
  const std::vector<SourceCount> counts = source_counts(database, field);
  std::string text;
  for (const SourceCount& count : counts) {
    text += (text.empty() ? "" : "; ") + (count.from.empty() ? std::string("not recorded (before format 7)") : count.from);
    if (counts.size() > 1) text += ", " + counted(count.clips, "clip");
  }
  return text;
}

nlohmann::json sources_json(const Database& database, std::string Clip::*field) {
  nlohmann::json out = nlohmann::json::array();
  for (const SourceCount& count : source_counts(database, field)) {
    out.push_back({{"from", count.from.empty() ? nlohmann::json() : nlohmann::json(count.from)}, {"clips", count.clips}});
  }
  return out;
}

}  // namespace

void print_units(const Database& database) {
  std::string units;
  for (const UnitCount& count : unit_counts(database)) {
    char text[128];
    if (count.value > 0.0f) {
      const char* name = unit_name(count.value);
      std::snprintf(text, sizeof(text), "%g metres per file unit%s%s%s", double(count.value), name ? " (" : "",
                    name ? name : "", name ? ")" : "");
    } else {
      std::snprintf(text, sizeof(text), "not recorded (built in code or before format 4)");
    }
    units += (units.empty() ? "" : "; ") + std::string(text);
    if (database.clips().size() > 1 && unit_counts(database).size() > 1) {
      units += ", " + counted(count.clips, "clip");
    }
  }
  std::printf("units: %s\n", units.c_str());
  std::printf("units taken from: %s\n", sources_text(database, &Clip::units_from).c_str());
  std::printf("up axis taken from: %s\n", sources_text(database, &Clip::axes_from).c_str());
  const std::optional<PoseFigures> figures = pose_figures(database);
  if (figures) {
    std::printf("standing height: %.2f m (highest joint above the lowest, 90th percentile of the frames; the "
                "top of the head is higher than its joint)\n",
                figures->height);
  } else {
    std::printf("standing height: unknown (no animation section)\n");
  }
  if (figures && figures->body_up) {
    // The axis the import stood the character along, measured: a wrong
    // up_axis shows here as a body lying down.
    std::printf("up axis: %s (the feet-to-head direction's y is %.2f on average; 1 = upright along +Y)\n",
                *figures->body_up >= 0.5 ? "+Y, upright" : "not +Y: the body is not upright (check import.up_axis)",
                *figures->body_up);
  }
  Result<crowd::GaitSpeeds> speeds = crowd::measure_gait_speeds(database);
  if (!speeds.ok()) {
    std::printf("speeds: not measured (%s)\n", speeds.message().c_str());
  } else if (speeds->has_run) {
    std::printf("speeds: walk %.2f m/s, run %.2f m/s%s\n", double(speeds->walk_mps), double(speeds->run_mps),
                speeds->tagged ? " (by the walk and run tags)" : "");
  } else {
    std::printf("speeds: walk %.2f m/s, no run (%s)\n", double(speeds->walk_mps), speeds->no_run_reason.c_str());
  }
}

nlohmann::json units_json(const Database& database) {
  nlohmann::json out;
  out["metres_per_unit"] = nlohmann::json::array();
  for (const UnitCount& count : unit_counts(database)) {
    const char* name = count.value > 0.0f ? unit_name(count.value) : nullptr;
    out["metres_per_unit"].push_back({{"value", count.value > 0.0f ? nlohmann::json(count.value) : nlohmann::json()},
                                      {"clips", count.clips},
                                      {"name", name ? nlohmann::json(name) : nlohmann::json()}});
  }
  out["units_from"] = sources_json(database, &Clip::units_from);
  out["axes_from"] = sources_json(database, &Clip::axes_from);
  const std::optional<PoseFigures> figures = pose_figures(database);
  out["standing_height_m"] = figures ? nlohmann::json(figures->height) : nlohmann::json();
  out["body_up"] = figures && figures->body_up ? nlohmann::json(*figures->body_up) : nlohmann::json();
  Result<crowd::GaitSpeeds> speeds = crowd::measure_gait_speeds(database);
  out["walk_mps"] = speeds.ok() ? nlohmann::json(speeds->walk_mps) : nlohmann::json();
  out["run_mps"] = speeds.ok() && speeds->has_run ? nlohmann::json(speeds->run_mps) : nlohmann::json();
  out["run_note"] = !speeds.ok() ? speeds.message() : speeds->no_run_reason;
  return out;
}

}  // namespace mmvk::cli
