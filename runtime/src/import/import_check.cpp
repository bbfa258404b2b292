// Measures of an imported motion, and the rule that stops a build whose
// units or axes are wrong (import_check.hpp).
#include "mmvk/import/import_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "mmvk/import/character.hpp"

namespace mmvk {

namespace {

float percentile(std::vector<float> values, double fraction) {
  if (values.empty()) return 0.0f;
  const auto at = values.begin() + std::ptrdiff_t(fraction * double(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

std::string number(double value, int digits = 3) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*g", digits, value);
  return text;
}

// The known unit that brings the measured height nearest a person's 1.7 m,
// with the height it gives ("0.01 (centimetres) gives 1.77 m").
std::string unit_suggestion(const ImportMeasures& measures, float used) {
  static constexpr struct {
    float value;
    const char* name;
  } kUnits[] = {{0.01f, "centimetres"}, {0.0254f, "inches"}, {0.05644f, "CMU ASF units"}, {1.0f, "metres"}};
  const auto* best = &kUnits[0];
  for (const auto& unit : kUnits) {
    const double height = measures.standing_height * unit.value / used;
    if (std::abs(std::log(height / 1.7)) < std::abs(std::log(measures.standing_height * best->value / used / 1.7))) best = &unit;
  }
  if (std::abs(best->value - used) <= 1e-3f * used) return "";
  return "; metres_per_unit " + number(best->value, 4) + " (" + best->name + ") gives " +
         number(measures.standing_height * best->value / used) + " m: set \"import\": {\"metres_per_unit\": " +
         number(best->value, 4) + "}";
}

std::string cause_units(const ImportMeasures& measures, const ImportContext& context) {
  return "Likely cause: the units: metres_per_unit " + number(context.metres_per_unit) + " (" + context.units_from +
         ")" + unit_suggestion(measures, context.metres_per_unit) + ".";
}

std::string cause_axis(const ImportContext& context) {
  const char* other = context.up_axis == UpAxis::Z ? "y" : "z";
  return std::string("Likely cause: the up axis (") + context.axes_from + "): if the file is " +
         (context.up_axis == UpAxis::Z ? "Y" : "Z") + "-up, set \"import\": {\"up_axis\": \"" + other + "\"}.";
}

}  // namespace

ImportMeasures measure_import(const Motion& motion) {
  ImportMeasures out;
  const Result<int> left = find_bone(motion.skeleton, "@left_foot"), right = find_bone(motion.skeleton, "@right_foot");
  const Result<int> head = find_bone(motion.skeleton, "@head");
  if (!left.ok() || !right.ok() || !head.ok() || motion.frame_count == 0) return out;
  out.human = true;
  const Result<int> hips = find_bone(motion.skeleton, "@hips");
  const std::size_t root = hips.ok() ? std::size_t(*hips) : 0;
  const std::size_t joints = motion.joint_count();
  std::vector<glm::vec3> positions(joints), next(joints);
  std::vector<glm::quat> rotations(joints);
  std::vector<float> heights, floors, speeds;
  double up = 0.0;
  constexpr std::uint32_t kFrames = 4096;
  const std::uint32_t count = std::min(motion.frame_count, kFrames);
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto frame = std::uint32_t(std::uint64_t{i} * motion.frame_count / count);
    forward_kinematics(motion, frame, positions, rotations);
    const auto [low, high] = std::minmax_element(positions.begin(), positions.end(),
                                                 [](const glm::vec3& a, const glm::vec3& b) { return a.y < b.y; });
    heights.push_back(high->y - low->y);
    floors.push_back(low->y);
    const glm::vec3 body = positions[std::size_t(*head)] -
                           0.5f * (positions[std::size_t(*left)] + positions[std::size_t(*right)]);
    const float length = glm::length(body);
    up += length > 0.0f ? body.y / length : 0.0;
    if (frame + 1 >= motion.frame_count) continue;
    forward_kinematics(motion, frame + 1, next, rotations);
    const glm::vec3 step = next[root] - positions[root];
    speeds.push_back(std::sqrt(step.x * step.x + step.z * step.z) * motion.fps);
  }
  out.standing_height = percentile(heights, 0.9);
  out.floor = percentile(floors, 0.5);
  out.body_up = float(up / count);
  out.root_speed = percentile(speeds, 0.5);
  return out;
}

Status check_import(const ImportMeasures& m, const ImportContext& context) {
  // Not a person, or a motion so corrupt that its figures overflow: the
  // build's feature limits then name the frame (database_build.hpp).
  if (!m.human || !std::isfinite(m.standing_height) || !std::isfinite(m.body_up) || !std::isfinite(m.floor) ||
      !std::isfinite(m.root_speed)) {
    return {};
  }
  const std::string head = context.source + ": implausible import: ";
  const std::string accept =
      " If the figures are right (not a person standing up, a giant, a crawl), set \"import\": "
      "{\"accept_implausible\": true} in the manifest.";
  if (!(m.body_up >= kMinBodyUp)) {
    return make_error(head + "the body is not upright along +Y (the feet-to-head direction's y is " +
                      number(m.body_up) + " on average, under " + number(kMinBodyUp) + "). " + cause_axis(context) +
                      accept);
  }
  if (!(m.standing_height >= kMinStandingHeight && m.standing_height <= kMaxStandingHeight)) {
    return make_error(head + "standing height " + number(m.standing_height) + " m, outside " +
                      number(kMinStandingHeight) + "-" + number(kMaxStandingHeight) + " m for a person. " +
                      cause_units(m, context) + accept);
  }
  if (!(m.floor >= -0.5f * m.standing_height)) {
    return make_error(head + "the lowest joint is " + number(-m.floor) + " m below the floor (y = 0) in the median frame, " +
                      "more than half the standing height. " + cause_axis(context) + accept);
  }
  const float limit = context.walk ? kMaxWalkSpeed : kMaxRootSpeed;
  if (!(m.root_speed <= limit)) {
    return make_error(head + "the hips move at " + number(m.root_speed) + " m/s (the median over frames), faster than " +
                      number(limit) + " m/s" + (context.walk ? " for a clip tagged \"walk\"" : "") +
                      ". Likely cause: the units (metres_per_unit " + number(context.metres_per_unit) + ", " +
                      context.units_from + ") or the file's frame rate." + accept);
  }
  return {};
}

}  // namespace mmvk
