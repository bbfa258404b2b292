#include "contact_report.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "mmvk/database/animation_data.hpp"

namespace mmvk::cli {

namespace {

// Above this horizontal speed a flagged point visibly slides (heel strikes
// and toe-offs are counted this way).
constexpr double kFastMetresPerSecond = 0.1;

// One point of one foot while one of its bits is set.
struct PointStats {
  const char* what = "";
  int joint = -1;
  std::uint8_t bit = 0;
  // The planted foot: on frames where only the heel is down, its speed is
  // the heel's (`heel_joint`, with `heel_only` the bits that say so).
  int heel_joint = -1;
  std::uint8_t heel_only[2] = {0, 0};  // {heel bit, toe bit}
  std::uint64_t frames = 0;       // frames with the bit
  double speed_sum = 0.0;         // m/s, over consecutive flagged frame pairs of a clip
  std::uint64_t pairs = 0;
  std::uint64_t fast_pairs = 0;   // pairs faster than kFastMetresPerSecond
  double fraction(std::uint32_t total) const { return total > 0 ? double(frames) / total : 0.0; }
  double mean_speed_cm_s() const {
    return pairs > 0 ? 100.0 * speed_sum / double(pairs) : std::numeric_limits<double>::quiet_NaN();
  }
  double fast_fraction() const {
    return pairs > 0 ? double(fast_pairs) / double(pairs) : std::numeric_limits<double>::quiet_NaN();
  }
};

// [side][planted, toe, heel]. The planted foot's speed is that of its point
// on the ground, as the crowd measures sliding (host/crowd/measure/motion_meter.hpp):
// the heel while only the heel bit is set, else the contact joint (the toe
// where there is one); a toe rolling down after a heel strike is no slide.
using FootStats = std::array<std::array<PointStats, 3>, 2>;

FootStats measure(const Database& database, const AnimationData& a) {
  FootStats out;
  for (int s = 0; s < 2; ++s) {
    const std::size_t side = static_cast<std::size_t>(s);
    const bool has_toe = a.contact_joints[side] >= 0 && a.contact_joints[side] != a.heel_joints[side];
    out[side] = {PointStats{"planted", a.contact_joints[side], contact_planted_bit(s), a.heel_joints[side],
                            {contact_heel_bit(s), contact_toe_bit(s)}},
                 PointStats{"toe", has_toe ? a.contact_joints[side] : -1, contact_toe_bit(s)},
                 PointStats{"heel", a.heel_joints[side], contact_heel_bit(s)}};
  }
  const std::size_t joints = a.joint_count();
  std::vector<glm::vec3> positions;
  std::vector<glm::quat> rotations;
  for (const Clip& clip : database.clips()) {
    Result<Motion> motion = clip_motion(a, database.fps(), clip.first_frame, clip.frame_count);
    if (!motion.ok()) continue;  // the database's own clips: cannot happen
    positions.resize(std::size_t{clip.frame_count} * joints);
    rotations.resize(positions.size());
    forward_kinematics_clip(*motion, positions, rotations);
    for (std::uint32_t f = 0; f < clip.frame_count; ++f) {
      const std::uint8_t bits = a.contacts[clip.first_frame + f];
      const std::uint8_t before = f > 0 ? a.contacts[clip.first_frame + f - 1] : 0;
      for (auto& foot : out) {
        for (PointStats& point : foot) {
          if (!(bits & point.bit)) continue;
          ++point.frames;
          const bool on_heel = point.heel_joint >= 0 && (bits & point.heel_only[0]) && !(bits & point.heel_only[1]);
          const int joint = on_heel ? point.heel_joint : point.joint;
          if (!(before & point.bit) || joint < 0) continue;
          const glm::vec3 p = positions[std::size_t{f} * joints + std::size_t(joint)];
          const glm::vec3 q = positions[std::size_t{f - 1} * joints + std::size_t(joint)];
          const double speed = std::hypot(double(p.x) - q.x, double(p.z) - q.z) * database.fps();
          point.speed_sum += speed;
          ++point.pairs;
          point.fast_pairs += speed > kFastMetresPerSecond ? 1 : 0;
        }
      }
    }
  }
  return out;
}

std::string joint_name(const AnimationData& a, int joint) {
  return joint < 0 ? std::string("none") : a.skeleton.names[static_cast<std::size_t>(joint)];
}

}  // namespace

void print_contacts(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) return;
  const FootContactParams& c = a->contact_params;
  if (a->legacy_contacts) {
    std::printf("contacts: from a format 2-4 file (3-D speed < %g m/s, height < %s%g m, no hysteresis or minimum "
                "duration); rebuild the database to relabel them\n",
                double(c.enter_speed), c.height_above_clip_floor ? "clip floor + " : "", double(c.enter_height));
  } else {
    std::printf("contacts: enter below %s%g m and %g m/s horizontal (over %.3g s), exit above %g m or %g m/s; "
                "shortest contact %g s, gap %g s\n",
                c.height_above_clip_floor ? "clip floor + " : "", double(c.enter_height), double(c.enter_speed),
                double(c.speed_step_seconds), double(c.exit_height), double(c.exit_speed),
                double(c.min_contact_seconds), double(c.min_gap_seconds));
  }
  std::printf("  %-6s %-8s %-16s %8s  %s\n", "foot", "point", "joint", "frames", "horizontal speed while flagged");
  const FootStats stats = measure(database, *a);
  for (std::size_t s = 0; s < 2; ++s) {
    for (const PointStats& point : stats[s]) {
      if (point.joint < 0 && point.frames == 0) continue;  // a skeleton without that point
      std::printf("  %-6s %-8s %-16s %7.1f%%  ", s == 0 ? "left" : "right", point.what,
                  joint_name(*a, point.joint).c_str(), 100.0 * point.fraction(a->frame_count));
      if (point.pairs == 0) {
        std::printf("-\n");
      } else {
        std::printf("mean %.2f cm/s, %.1f%% of frame pairs above %g cm/s\n", point.mean_speed_cm_s(),
                    100.0 * point.fast_fraction(), 100.0 * kFastMetresPerSecond);
      }
    }
  }
}

nlohmann::json contacts_json(const Database& database) {
  const AnimationData* a = database.animation();
  if (a == nullptr) return nullptr;
  const FootContactParams& c = a->contact_params;
  nlohmann::json out;
  out["toe_joints"] = {joint_name(*a, a->contact_joints[0]), joint_name(*a, a->contact_joints[1])};
  out["heel_joints"] = {joint_name(*a, a->heel_joints[0]), joint_name(*a, a->heel_joints[1])};
  out["legacy"] = a->legacy_contacts;
  nlohmann::json& params = out["params"];
  for_each_contact_bone(c, [&](const char* name, const std::string& bone) { params[name] = bone; });
  for_each_contact_number(c, [&](const char* name, float value) { params[name] = value; });
  params["height_above_clip_floor"] = c.height_above_clip_floor;
  const FootStats stats = measure(database, *a);
  for (std::size_t s = 0; s < 2; ++s) {
    nlohmann::json foot;
    for (const PointStats& point : stats[s]) {
      // NaN (no flagged pairs) becomes JSON null.
      foot[point.what] = {{"joint", joint_name(*a, point.joint)},
                          {"frames", point.frames},
                          {"fraction", point.fraction(a->frame_count)},
                          {"mean_speed_cm_s", point.mean_speed_cm_s()},
                          {"fast_fraction", point.fast_fraction()}};
    }
    out["feet"][s == 0 ? "left" : "right"] = std::move(foot);
  }
  return out;
}

}  // namespace mmvk::cli
