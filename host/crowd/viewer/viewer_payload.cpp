// Layout of the raw blob (all integers are LEB128 varints; "z" marks a
// zigzag-coded signed value; every coordinate is quantized before the deltas
// are taken, so decoding accumulates exactly and never drifts):
//   roots     for agent, for sample: z dx_cm, z dz_cm   (delta along time)
//   facings   for agent, for sample: z d_q               (q = 1/4096 turn, delta wrapped to +-2048)
//   frames    for agent, for sample: z d(pose_slot + 1)  (0: no pose)
//   desired   for agent, for sample, for point: z d_rel_x_cm, z d_rel_z_cm
//             (rel = point - root at that sample; delta along time per point)
//   matched   same as desired, present when meta.has_matched
//   goals     for agent: count, then for goal: z dx_cm, z dz_cm
//   searches  for agent: count, then for event: z dt_ms, flags (1 jumped,
//             2 forced, 4 has to_frame), z d_from_frame, [z to - from], z cost_milli
//   pose_frames  for slot: z d_frame
//   poses     for slot, joint, axis: z d_mm (delta against the previous slot)
//   legs      present when meta.leg_joints is not empty: for agent, for
//             sample, for leg joint, axis: z, in steps of 2 mm, the
//             displayed position in the character space of the sample's
//             quantized root and facing minus the played frame's pose (its
//             slot's joint in mm; 0 without a pose): the correction that
//             sub-frame playback, inertialization and foot IK add (median
//             2 mm, p99 6 cm on the CMU walks); 2 mm steps cost a third less
//             than 1 mm and are half a pixel at the viewer's closest zoom
//   feet      present when meta.has_feet: for agent: count, then for event:
//             z dt_ms, state, and for each locked foot (bits 2, 3 of state):
//             z dx_mm, z dy_mm, z dz_mm (delta against that foot's previous
//             anchor, world)
//   detail    present when meta.detail.agents > 0: for detail agent, u its
//             index less the previous detail agent's + 1 (0 for each of
//             the first N characters in a row); then for detail agent, for
//             detail sample, for joint, axis: z, in mm, of joint 0's world
//             position and of every other joint's position less joint 0's
//             (the body moves less than the world between ticks), less its
//             linear prediction from the agent's two previous samples
//             (2 v[s-1] - v[s-2]; v[s-1] at the second sample, 0 at the
//             first): smooth motion at the tick rate leaves residuals of a
//             few mm
//   why       present when meta.why is not null: for agent: count, then for
//             explained search: z d_search (against the previous one), for
//             channel: z weight_milli; z continuing_bias_1e5,
//             z continuing_multiplier_milli; then the chosen and the
//             continuing frame: u present, and when present: u frame,
//             u clip, z clip_time_ms, z multiplier_milli, z bias_1e5,
//             z cost_1e5, u exclusion, for channel: z weighted_1e5
#include "viewer/viewer_payload.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <nlohmann/json.hpp>
#include <zlib.h>

namespace mmvk::crowd {
namespace {

class VarintWriter {
 public:
  explicit VarintWriter(std::vector<uint8_t>& out) : out_(out) {}
  void u(uint64_t value) {
    while (value >= 0x80) {
      out_.push_back(static_cast<uint8_t>(value | 0x80));
      value >>= 7;
    }
    out_.push_back(static_cast<uint8_t>(value));
  }
  void z(int64_t value) { u((static_cast<uint64_t>(value) << 1) ^ static_cast<uint64_t>(value >> 63)); }

 private:
  std::vector<uint8_t>& out_;
};

// The page decodes varints with doubles: keep every value well inside 2^53.
constexpr double kLimit = 1e14;

int64_t quantize(double value, double scale) {
  return static_cast<int64_t>(std::llround(std::clamp(value * scale, -kLimit, kLimit)));
}

constexpr double kCm = 100.0;
constexpr double kMm = 1000.0;
constexpr double kMilli = 1000.0;
constexpr int64_t kTurn = 4096;
constexpr int64_t kLegStepMm = 2;
// Channel costs are often well under a thousandth.
constexpr double kCost = 1e5;

// Appends one section and records its size in the header.
template <class Fill>
void add_section(nlohmann::json& sections, std::vector<uint8_t>& raw, const char* name, Fill&& fill) {
  const std::size_t before = raw.size();
  VarintWriter out(raw);
  fill(out);
  sections.push_back({{"name", name}, {"bytes", raw.size() - before}});
}

// Maps each sample's database frame to a slot among the poses actually
// played, so frames recorded but never shown cost nothing in the page.
struct PoseSlots {
  std::vector<int64_t> sample_slot;  // [agent x sample layout of Recording::frame], -1: none
  std::vector<std::size_t> poses;    // slot -> index into Recording::pose_frames
};

PoseSlots assign_pose_slots(const Recording& r) {
  PoseSlots slots;
  std::vector<int64_t> pose_slot(r.pose_frames.size(), -1);
  slots.sample_slot.assign(r.frame.size(), -1);
  std::vector<std::size_t> found(r.frame.size(), r.pose_frames.size());
  for (std::size_t i = 0; i < r.frame.size(); ++i) {
    const auto it = std::lower_bound(r.pose_frames.begin(), r.pose_frames.end(), r.frame[i]);
    if (it != r.pose_frames.end() && *it == r.frame[i]) {
      found[i] = static_cast<std::size_t>(it - r.pose_frames.begin());
      pose_slot[found[i]] = 0;
    }
  }
  // Slots in ascending frame order, so neighbouring slots are similar poses.
  for (std::size_t p = 0; p < pose_slot.size(); ++p) {
    if (pose_slot[p] == 0) {
      pose_slot[p] = static_cast<int64_t>(slots.poses.size());
      slots.poses.push_back(p);
    }
  }
  for (std::size_t i = 0; i < r.frame.size(); ++i) {
    if (found[i] < pose_slot.size()) slots.sample_slot[i] = pose_slot[found[i]];
  }
  return slots;
}

void write_trajectory(VarintWriter& out, const Recording& r, const std::vector<float>& xs,
                      const std::vector<float>& zs) {
  const std::size_t points = r.trajectory_points();
  std::vector<int64_t> previous(points * 2);
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    std::fill(previous.begin(), previous.end(), 0);
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      const std::size_t root = r.sample_index(s, a);
      const int64_t root_x = quantize(r.root_x[root], kCm);
      const int64_t root_z = quantize(r.root_z[root], kCm);
      for (std::size_t k = 0; k < points; ++k) {
        const std::size_t i = r.trajectory_index(s, a, k);
        const int64_t rel_x = quantize(xs[i], kCm) - root_x;
        const int64_t rel_z = quantize(zs[i], kCm) - root_z;
        out.z(rel_x - previous[2 * k]);
        out.z(rel_z - previous[2 * k + 1]);
        previous[2 * k] = rel_x;
        previous[2 * k + 1] = rel_z;
      }
    }
  }
}

void write_searches(VarintWriter& out, const Recording& r) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    out.u(r.searches[a].size());
    int64_t previous_ms = 0;
    int64_t previous_from = 0;
    for (const SearchEvent& event : r.searches[a]) {
      const int64_t ms = quantize(event.time_s, kMilli);
      const bool has_to = event.to_frame >= 0;
      out.z(ms - previous_ms);
      out.u((event.jumped ? 1u : 0u) | (event.forced ? 2u : 0u) | (has_to ? 4u : 0u));
      out.z(int64_t{event.from_frame} - previous_from);
      if (has_to) out.z(int64_t{event.to_frame} - event.from_frame);
      out.z(quantize(std::isfinite(event.cost) ? event.cost : kLimit, kMilli));
      previous_ms = ms;
      previous_from = event.from_frame;
    }
  }
}

// The facing as the page decodes it: q / 4096 of a turn, q in [0, 4096).
int64_t facing_steps(float facing) {
  const double turns = facing / (2.0 * std::numbers::pi);
  return ((quantize(turns, kTurn) % kTurn) + kTurn) % kTurn;
}

void write_legs(VarintWriter& out, const Recording& r, const PoseSlots& slots) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      // The root as the page decodes it, so it rebuilds the world positions
      // to the millimetre.
      const std::size_t i = r.sample_index(s, a);
      const double x = double(quantize(r.root_x[i], kCm)) / kCm, z = double(quantize(r.root_z[i], kCm)) / kCm;
      const double f = double(facing_steps(r.facing[i])) / double(kTurn) * 2.0 * std::numbers::pi;
      const double c = std::cos(f), sn = std::sin(f);
      const int64_t slot = slots.sample_slot[i];
      for (std::size_t l = 0; l < r.leg_joints.size(); ++l) {
        const float* p = r.leg_positions.data() + r.leg_index(s, a, l);
        // world = root + (c x + s z, y, -s x + c z): invert it.
        const double dx = p[0] - x, dz = p[2] - z;
        const double local[3] = {c * dx - sn * dz, p[1], sn * dx + c * dz};
        for (std::size_t k = 0; k < 3; ++k) {
          const int64_t frame_mm =
              slot < 0 ? 0
                       : quantize(r.pose_positions[r.pose_index(slots.poses[std::size_t(slot)],
                                                                std::size_t(r.leg_joints[l])) + k],
                                  kMm);
          out.z(quantize((local[k] * kMm - double(frame_mm)) / double(kLegStepMm), 1.0));
        }
      }
    }
  }
}

void write_feet(VarintWriter& out, const Recording& r) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    out.u(r.foot_events[a].size());
    int64_t previous_ms = 0;
    int64_t previous_anchor[2][3] = {};
    for (const FootEvent& event : r.foot_events[a]) {
      const int64_t ms = quantize(event.time_s, kMilli);
      out.z(ms - previous_ms);
      out.u(event.state);
      previous_ms = ms;
      for (std::size_t foot = 0; foot < 2; ++foot) {
        if (!(event.state & (foot == 0 ? kFootLockedLeft : kFootLockedRight))) continue;
        for (std::size_t c = 0; c < 3; ++c) {
          const int64_t mm = quantize(event.anchor[foot][c], kMm);
          out.z(mm - previous_anchor[foot][c]);
          previous_anchor[foot][c] = mm;
        }
      }
    }
  }
}

void write_detail(VarintWriter& out, const Recording& r) {
  std::uint64_t next = 0;
  for (const std::uint32_t a : r.detail_agents) {
    out.u(a - next);
    next = std::uint64_t(a) + 1;
  }
  const std::size_t joints = r.joint_count();
  std::vector<int64_t> previous(joints * 3), before(joints * 3);
  for (std::size_t a = 0; a < r.detail_agents.size(); ++a) {
    for (std::size_t s = 0; s < r.detail_sample_count; ++s) {
      const float* root = r.detail_positions.data() + r.detail_index(s, a, 0);
      for (std::size_t j = 0; j < joints; ++j) {
        const float* p = r.detail_positions.data() + r.detail_index(s, a, j);
        for (std::size_t k = 0; k < 3; ++k) {
          const std::size_t c = 3 * j + k;
          const int64_t mm = j == 0 ? quantize(p[k], kMm) : quantize(p[k], kMm) - quantize(root[k], kMm);
          const int64_t predicted = s == 0 ? 0 : s == 1 ? previous[c] : 2 * previous[c] - before[c];
          out.z(mm - predicted);
          before[c] = previous[c];
          previous[c] = mm;
        }
      }
    }
  }
}

void write_frame_why(VarintWriter& out, const Recording::FrameWhy& f) {
  out.u(f.frame >= 0 ? 1u : 0u);
  if (f.frame < 0) return;
  out.u(std::uint64_t(f.frame));
  out.u(f.clip);
  out.z(quantize(f.clip_time_s, kMilli));
  out.z(quantize(f.multiplier, kMilli));
  out.z(quantize(f.bias, kCost));
  out.z(quantize(f.cost, kCost));
  out.u(f.exclusion);
  for (float v : f.weighted) out.z(quantize(v, kCost));
}

void write_why(VarintWriter& out, const Recording& r) {
  for (const auto& explained : r.why) {
    out.u(explained.size());
    int64_t previous = 0;
    for (const Recording::SearchWhy& why : explained) {
      out.z(int64_t(why.search) - previous);
      previous = int64_t(why.search);
      for (float w : why.weights) out.z(quantize(w, kMilli));
      out.z(quantize(why.continuing_bias, kCost));
      out.z(quantize(why.continuing_multiplier, kMilli));
      write_frame_why(out, why.chosen);
      write_frame_why(out, why.continuing);
    }
  }
}

nlohmann::json bounds_of(const Recording& r) {
  float min_x = INFINITY, min_z = INFINITY, max_x = -INFINITY, max_z = -INFINITY;
  auto grow = [&](float x, float z) {
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_z = std::min(min_z, z), max_z = std::max(max_z, z);
  };
  for (std::size_t i = 0; i < r.root_x.size(); ++i) grow(r.root_x[i], r.root_z[i]);
  for (const auto& goals : r.goals) {
    for (const auto& goal : goals) grow(goal.x, goal.z);
  }
  if (min_x > max_x) return {-10.0, -10.0, 10.0, 10.0};
  return {min_x, min_z, max_x, max_z};
}

Result<std::vector<uint8_t>> deflate_bytes(const std::vector<uint8_t>& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> out(size);
  const int rc = compress2(out.data(), &size, raw.data(), static_cast<uLong>(raw.size()), 6);
  if (rc != Z_OK) return make_error("viewer: deflate of the recording failed (zlib error " + std::to_string(rc) + ")");
  out.resize(size);
  return out;
}

// The sections of the payload, each a stream of varints (the page decodes
// them in viewer.js): deltas per agent over its samples.
void write_roots(VarintWriter& out, const Recording& r) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    int64_t px = 0, pz = 0;
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      const int64_t x = quantize(r.root_x[r.sample_index(s, a)], kCm);
      const int64_t z = quantize(r.root_z[r.sample_index(s, a)], kCm);
      out.z(x - px);
      out.z(z - pz);
      px = x, pz = z;
    }
  }
}

void write_facings(VarintWriter& out, const Recording& r) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    int64_t previous = 0;
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      const int64_t q = facing_steps(r.facing[r.sample_index(s, a)]);
      int64_t delta = q - previous;
      if (delta >= kTurn / 2) delta -= kTurn;
      if (delta < -kTurn / 2) delta += kTurn;
      out.z(delta);
      previous = q;
    }
  }
}

void write_frames(VarintWriter& out, const Recording& r, const PoseSlots& slots) {
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    int64_t previous = 0;
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      const int64_t value = slots.sample_slot[r.sample_index(s, a)] + 1;
      out.z(value - previous);
      previous = value;
    }
  }
}

void write_goals(VarintWriter& out, const Recording& r) {
  for (const auto& goals : r.goals) {
    out.u(goals.size());
    int64_t px = 0, pz = 0;
    for (const auto& goal : goals) {
      const int64_t x = quantize(goal.x, kCm), z = quantize(goal.z, kCm);
      out.z(x - px);
      out.z(z - pz);
      px = x, pz = z;
    }
  }
}

void write_pose_frames(VarintWriter& out, const Recording& r, const PoseSlots& slots) {
  int64_t previous = 0;
  for (std::size_t p : slots.poses) {
    out.z(int64_t{r.pose_frames[p]} - previous);
    previous = r.pose_frames[p];
  }
}

void write_poses(VarintWriter& out, const Recording& r, const PoseSlots& slots) {
  std::vector<int64_t> previous(r.joint_count() * 3, 0);
  for (std::size_t p : slots.poses) {
    for (std::size_t c = 0; c < previous.size(); ++c) {
      const int64_t mm = quantize(r.pose_positions[r.pose_index(p, 0) + c], kMm);
      out.z(mm - previous[c]);
      previous[c] = mm;
    }
  }
}

// The payload's metadata as JSON for a <script> block: '<' only occurs
// inside JSON strings, where \u003c means the same; this keeps a title such
// as "</script>" from ending the page's script block.
std::string meta_json(const Recording& r, const PoseSlots& slots, const nlohmann::json& sections,
                      std::size_t raw_bytes) {
  const nlohmann::json meta = {
      {"format", 2},  // 2: the detail section starts with its characters
      {"title", r.title},
      {"sample_rate_hz", r.sample_rate_hz},
      {"agent_count", r.agent_count},
      {"sample_count", r.sample_count},
      {"trajectory_times_s", r.trajectory_times_s},
      {"has_matched", !r.matched_x.empty()},
      {"joint_names", r.joint_names},
      {"joint_parents", r.joint_parents},
      {"pose_count", slots.poses.size()},
      {"leg_joints", r.leg_joints},
      {"has_feet", !r.foot_events.empty()},
      {"detail", {{"agents", r.detail_agents.size()}, {"sample_count", r.detail_sample_count}, {"rate_hz", r.detail_rate_hz}}},
      {"why", r.why.empty() ? nlohmann::json(nullptr)
                            : nlohmann::json{{"channel_names", r.channel_names},
                                                              {"clip_names", r.clip_names},
                                                              {"exclusion_names", r.exclusion_names}}},
      {"bounds", bounds_of(r)},
      {"sections", sections},
      {"raw_bytes", raw_bytes},
  };
  std::string json = meta.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string escaped;
  escaped.reserve(json.size());
  for (char c : json) {
    if (c == '<') {
      escaped += "\\u003c";
    } else {
      escaped += c;
    }
  }
  return escaped;
}

}  // namespace

Result<ViewerPayload> encode_viewer_payload(const Recording& r) {
  ViewerPayload payload;
  nlohmann::json sections = nlohmann::json::array();
  std::vector<uint8_t>& raw = payload.raw;
  const PoseSlots slots = assign_pose_slots(r);

  add_section(sections, raw, "roots", [&](VarintWriter& out) { write_roots(out, r); });
  add_section(sections, raw, "facings", [&](VarintWriter& out) { write_facings(out, r); });
  add_section(sections, raw, "frames", [&](VarintWriter& out) { write_frames(out, r, slots); });
  add_section(sections, raw, "desired",
              [&](VarintWriter& out) { write_trajectory(out, r, r.desired_x, r.desired_z); });
  if (!r.matched_x.empty()) {
    add_section(sections, raw, "matched",
                [&](VarintWriter& out) { write_trajectory(out, r, r.matched_x, r.matched_z); });
  }
  add_section(sections, raw, "goals", [&](VarintWriter& out) { write_goals(out, r); });
  add_section(sections, raw, "searches", [&](VarintWriter& out) { write_searches(out, r); });
  add_section(sections, raw, "pose_frames", [&](VarintWriter& out) { write_pose_frames(out, r, slots); });
  add_section(sections, raw, "poses", [&](VarintWriter& out) { write_poses(out, r, slots); });
  if (!r.leg_joints.empty()) add_section(sections, raw, "legs", [&](VarintWriter& out) { write_legs(out, r, slots); });
  if (!r.foot_events.empty()) add_section(sections, raw, "feet", [&](VarintWriter& out) { write_feet(out, r); });
  if (!r.detail_agents.empty()) add_section(sections, raw, "detail", [&](VarintWriter& out) { write_detail(out, r); });
  if (!r.why.empty()) add_section(sections, raw, "why", [&](VarintWriter& out) { write_why(out, r); });

  MMVK_ASSIGN_OR_RETURN(payload.compressed, deflate_bytes(raw));
  payload.meta_json = meta_json(r, slots, sections, raw.size());
  return payload;
}

}  // namespace mmvk::crowd
