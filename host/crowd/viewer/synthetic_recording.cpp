#include "viewer/synthetic_recording.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace mmvk::crowd {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// The synthetic database: a walk clip and a run clip at the simulation fps.
struct Clip {
  int32_t first;
  int32_t length;
  float cycle_frames;  // frames per gait cycle (two steps)
  float stride;        // leg swing amplitude, radians
};
constexpr Clip kWalk{0, 120, 32.0f, 0.45f};
constexpr Clip kRun{200, 60, 20.0f, 0.8f};

void set_skeleton(Recording& r) {
  r.joint_names = {"Hips",      "Spine",      "Chest",     "Neck",        "Head",         "LeftShoulder", "LeftElbow",
                   "LeftHand",  "RightShoulder", "RightElbow", "RightHand", "LeftUpLeg", "LeftLeg",      "LeftFoot",
                   "LeftToe",   "RightUpLeg", "RightLeg",  "RightFoot",   "RightToe"};
  r.joint_parents = {-1, 0, 1, 2, 3, 2, 5, 6, 2, 8, 9, 0, 11, 12, 13, 0, 15, 16, 17};
}

// Character space: +Z forward, +Y up, the character's left is +X.
void append_pose(Recording& r, const Clip& clip, int32_t frame) {
  const float phase = 2.0f * kPi * static_cast<float>(frame - clip.first) / clip.cycle_frames;
  const float bob = 0.03f * std::cos(2.0f * phase);
  const float hip_y = 0.95f + bob;
  const float lean = clip.stride > 0.6f ? 0.15f : 0.04f;
  std::vector<float> p;
  auto add = [&](float x, float y, float z) { p.insert(p.end(), {x, y, z}); };
  add(0, hip_y, 0);                                       // Hips
  add(0, hip_y + 0.2f, 0.2f * lean);                      // Spine
  add(0, hip_y + 0.5f, 0.5f * lean);                      // Chest
  add(0, hip_y + 0.6f, 0.6f * lean);                      // Neck
  add(0, hip_y + 0.75f, 0.75f * lean + 0.03f);            // Head
  for (float side : {1.0f, -1.0f}) {                      // arms swing against the legs
    const float swing = -side * 0.6f * clip.stride * std::sin(phase);
    const float sx = side * 0.2f, sy = hip_y + 0.5f, sz = 0.5f * lean;
    const float ex = sx + side * 0.03f, ey = sy - 0.28f * std::cos(swing), ez = sz + 0.28f * std::sin(swing);
    const float bend = swing + 0.3f + 0.4f * clip.stride;
    add(sx, sy, sz);
    add(ex, ey, ez);
    add(ex, ey - 0.26f * std::cos(bend), ez + 0.26f * std::sin(bend));
  }
  for (float side : {1.0f, -1.0f}) {
    const float leg_phase = side > 0 ? phase : phase + kPi;
    const float thigh = clip.stride * std::sin(leg_phase);
    // The knee bends while the leg swings forward (the second half of the cycle).
    const float knee = std::max(0.0f, std::sin(leg_phase + 0.5f * kPi)) * clip.stride * 1.4f + 0.05f;
    const float hx = side * 0.1f;
    const float ky = hip_y - 0.45f * std::cos(thigh), kz = 0.45f * std::sin(thigh);
    const float ay = ky - 0.45f * std::cos(thigh - knee), az = kz + 0.45f * std::sin(thigh - knee);
    add(hx, hip_y, 0);
    add(hx, ky, kz);
    add(hx, std::max(ay, 0.08f), az);
    add(hx, std::max(ay - 0.06f, 0.02f), az + 0.14f);
  }
  r.pose_frames.push_back(frame);
  r.pose_positions.insert(r.pose_positions.end(), p.begin(), p.end());
}

struct Agent {
  float centre_x, centre_z, radius, speed, angle0;
  bool running;
};

// The feet's events (a foot is planted while its ankle rests at the pose's
// floor clamp, and locked where its toe was when it touched down) and the
// legs' world positions at every sample: the played pose placed at the
// root, a locked foot's ankle and toe moved to hold the toe on its anchor
// (the knee half as far), as a crude foot IK would.
void add_feet(Recording& r) {
  r.leg_joints = {12, 13, 14, 16, 17, 18};  // below LeftUpLeg and RightUpLeg
  constexpr int32_t kAnkles[2] = {13, 17}, kToes[2] = {14, 18};
  const std::size_t legs = r.leg_joints.size();
  r.leg_positions.assign(r.sample_count * r.agent_count * legs * 3, 0.0f);
  r.foot_events.assign(r.agent_count, {});
  for (std::size_t a = 0; a < r.agent_count; ++a) {
    FootEvent current;
    current.state = 0xff;  // none yet: the first sample always adds one
    for (std::size_t s = 0; s < r.sample_count; ++s) {
      const std::size_t i = r.sample_index(s, a);
      const auto pose = std::size_t(std::lower_bound(r.pose_frames.begin(), r.pose_frames.end(), r.frame[i]) -
                                    r.pose_frames.begin());
      const float c = std::cos(r.facing[i]), sn = std::sin(r.facing[i]);
      auto world = [&](int32_t joint) {
        const float* q = r.pose_positions.data() + r.pose_index(pose, std::size_t(joint));
        return std::array<float, 3>{r.root_x[i] + c * q[0] + sn * q[2], q[1], r.root_z[i] - sn * q[0] + c * q[2]};
      };
      FootEvent next = current;
      next.time_s = float(s) / r.sample_rate_hz;
      next.state = 0;
      for (int foot = 0; foot < 2; ++foot) {
        const bool planted = r.pose_positions[r.pose_index(pose, std::size_t(kAnkles[foot])) + 1] <= 0.0801f;
        const bool was_locked = current.state != 0xff && (current.state & (kFootLockedLeft << foot));
        if (!planted) {
          next.anchor[std::size_t(foot)] = {0.0f, 0.0f, 0.0f};
          continue;
        }
        next.state |= std::uint8_t((kFootPlantedLeft | kFootLockedLeft) << foot);
        if (!was_locked) next.anchor[std::size_t(foot)] = world(kToes[foot]);
      }
      if (next.state != current.state) {
        r.foot_events[a].push_back(next);
        current = next;
      }
      for (std::size_t l = 0; l < legs; ++l) {
        auto p = world(r.leg_joints[l]);
        const int foot = l < 3 ? 0 : 1;
        if (current.state & (kFootLockedLeft << foot)) {
          const auto toe = world(kToes[foot]);
          const auto& anchor = current.anchor[std::size_t(foot)];
          const float share = l % 3 == 0 ? 0.5f : 1.0f;  // the knee, then the ankle and the toe
          p[0] += share * (anchor[0] - toe[0]);
          p[2] += share * (anchor[2] - toe[2]);
        }
        std::copy(p.begin(), p.end(), r.leg_positions.begin() + std::ptrdiff_t(r.leg_index(s, a, l)));
      }
    }
  }
}

using Rng = std::mt19937;

float unit(Rng& rng) { return std::uniform_real_distribution<float>(0.0f, 1.0f)(rng); }

// Agents on a square grid, 6 m apart, each walking its own circle.
std::vector<Agent> place_agents(std::size_t n, Rng& rng) {
  const std::size_t side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  std::vector<Agent> agents(n);
  for (std::size_t a = 0; a < n; ++a) {
    Agent& g = agents[a];
    g.running = unit(rng) < 0.15f;
    g.centre_x = 6.0f * static_cast<float>(a % side) + unit(rng);
    g.centre_z = 6.0f * static_cast<float>(a / side) + unit(rng);
    g.radius = 1.5f + 1.2f * unit(rng);
    g.speed = (g.running ? 3.2f : 1.2f + 0.4f * unit(rng)) * (unit(rng) < 0.5f ? 1.0f : -1.0f);
    g.angle0 = 2.0f * kPi * unit(rng);
  }
  return agents;
}

// Position on the circle at time t, with a small sway so the achieved path
// differs visibly from the desired one.
void circle(const Agent& g, float t, float sway, float& x, float& z) {
  const float angle = g.angle0 + g.speed / g.radius * t;
  const float radius = g.radius + sway;
  x = g.centre_x + radius * std::sin(angle);
  z = g.centre_z + radius * std::cos(angle);
}

// A search at time t from `frame`: about one jump a second. Moves `offset`
// (the frame's place in its clip) where it jumps.
SearchEvent random_search(const SyntheticRecordingParams& params, const Clip& clip, float t, int32_t frame,
                          int32_t& offset, Rng& rng) {
  SearchEvent event;
  event.time_s = t;
  event.from_frame = frame;
  event.jumped = unit(rng) < params.search_interval_s;
  event.forced = event.jumped && unit(rng) < 0.1f;
  const int32_t jump_to = static_cast<int32_t>(unit(rng) * static_cast<float>(clip.length - 1));
  event.to_frame = event.jumped ? clip.first + jump_to : frame;
  event.cost = event.jumped ? 0.4f + 1.5f * unit(rng) : 1.5f + 2.0f * unit(rng);
  if (event.jumped) offset = jump_to;
  return event;
}

// Sample `sample` of agent a at time t: its root, facing, frame and trajectories.
void record_sample(Recording& r, const Agent& g, std::size_t sample, std::size_t a, float t, float sway,
                   int32_t frame) {
  const std::size_t i = r.sample_index(sample, a);
  circle(g, t, sway, r.root_x[i], r.root_z[i]);
  float ax, az;
  circle(g, t + 0.05f, sway, ax, az);
  r.facing[i] = std::atan2(ax - r.root_x[i], az - r.root_z[i]);
  r.frame[i] = frame;
  for (std::size_t p = 0; p < r.trajectory_points(); ++p) {
    const std::size_t j = r.trajectory_index(sample, a, p);
    const float ahead = r.trajectory_times_s[p];
    circle(g, t + ahead, 0.0f, r.desired_x[j], r.desired_z[j]);
    circle(g, t + ahead * 0.93f, sway * 0.5f, r.matched_x[j], r.matched_z[j]);
  }
}

// Agent a's goals, searches and samples, tick by tick.
void simulate_agent(Recording& r, const SyntheticRecordingParams& params, const Agent& g, std::size_t a, Rng& rng) {
  const Clip& clip = g.running ? kRun : kWalk;
  const float dt = 1.0f / params.simulation_rate_hz;
  const std::size_t ticks = static_cast<std::size_t>(std::ceil(params.seconds * params.simulation_rate_hz)) + 1;
  const int search_ticks = std::max(1, static_cast<int>(std::lround(params.search_interval_s / dt)));
  for (int k = 0; k < 8; ++k) {
    float x, z;
    circle(g, (static_cast<float>(k) + 1.0f) * 2.0f * kPi * g.radius / std::abs(g.speed) / 8.0f, 0.0f, x, z);
    r.goals[a].push_back({x, z});
  }
  int32_t offset = static_cast<int32_t>(unit(rng) * static_cast<float>(clip.length));
  std::size_t next_sample = 0;
  const float sway_phase = 2.0f * kPi * unit(rng);
  for (std::size_t tick = 0; tick < ticks && next_sample < r.sample_count; ++tick) {
    const float t = static_cast<float>(tick) * dt;
    const int32_t frame = clip.first + offset;
    if (static_cast<int>(tick + a) % search_ticks == 0) {  // staggered searches
      r.searches[a].push_back(random_search(params, clip, t, frame, offset, rng));
    }
    if (static_cast<float>(next_sample) / params.sample_rate_hz <= t + 0.5f * dt) {
      const float sway = 0.15f * std::sin(1.3f * t + sway_phase);
      record_sample(r, g, next_sample, a, t, sway, clip.first + offset);
      ++next_sample;
    }
    offset = (offset + 1) % clip.length;
  }
}

// The detailed agents' whole pose at the simulation rate: each 10 Hz
// sample's played pose in world space, held until the next sample, its arms
// lifted by a few centimetres (as the displayed pose differs from the
// played one).
void add_detail(Recording& r, const SyntheticRecordingParams& params) {
  r.detail_agents = params.detail_set;
  if (params.detail_set.empty()) {
    for (std::uint32_t a = 0; a < std::min(params.detail_agents, r.agent_count); ++a) r.detail_agents.push_back(a);
  }
  r.detail_rate_hz = params.simulation_rate_hz;
  r.detail_sample_count = static_cast<std::size_t>(std::floor(params.seconds * params.simulation_rate_hz)) + 1;
  const std::size_t joints = r.joint_count();
  for (std::size_t k = 0; k < r.detail_sample_count; ++k) {
    const float t = static_cast<float>(k) / r.detail_rate_hz;
    const std::size_t sample = std::min(r.sample_count - 1, static_cast<std::size_t>(t * r.sample_rate_hz + 1e-3f));
    for (const std::uint32_t a : r.detail_agents) {
      const std::size_t i = r.sample_index(sample, a);
      const auto pose = std::lower_bound(r.pose_frames.begin(), r.pose_frames.end(), r.frame[i]) - r.pose_frames.begin();
      const float c = std::cos(r.facing[i]), s = std::sin(r.facing[i]);
      for (std::size_t j = 0; j < joints; ++j) {
        const float* p = r.pose_positions.data() + r.pose_index(static_cast<std::size_t>(pose), j);
        const float lift = p[1] > 1.0f ? 0.03f : 0.0f;
        r.detail_positions.insert(r.detail_positions.end(),
                                  {r.root_x[i] + c * p[0] + s * p[2], p[1] + lift, r.root_z[i] - s * p[0] + c * p[2]});
      }
    }
  }
}

Recording::FrameWhy synthetic_frame_why(int32_t frame, const std::vector<float>& weights, Rng& rng) {
  Recording::FrameWhy f;
  f.frame = frame;
  f.clip = frame >= kRun.first ? 1 : 0;
  f.clip_time_s = static_cast<float>(frame - (f.clip ? kRun.first : kWalk.first)) / 30.0f;
  float sum = 0.0f;
  for (float w : weights) {
    f.weighted.push_back(w * (0.01f + unit(rng)));
    sum += f.weighted.back();
  }
  f.multiplier = 1.0f;
  f.bias = f.clip ? 0.05f : 0.0f;
  f.cost = f.multiplier * sum + f.bias;
  return f;
}

// Every search of the detailed agents explained: made-up channel costs of
// the chosen and the continuing frame (the next one, the played frame's).
void add_why(Recording& r, Rng& rng) {
  r.channel_names = {"trajectory_position", "trajectory_direction", "left_foot_position", "hip_velocity"};
  r.clip_names = {"synthetic walk", "synthetic run"};
  r.exclusion_names = {"candidate", "excluded"};
  r.why.assign(r.agent_count, {});
  const std::vector<float> weights = {1.0f, 1.5f, 0.75f, 1.0f};
  for (const std::uint32_t a : r.detail_agents) {
    for (std::size_t e = 0; e < r.searches[a].size(); ++e) {
      const SearchEvent& event = r.searches[a][e];
      Recording::SearchWhy why;
      why.search = e;
      why.weights = weights;
      why.continuing_bias = -0.1f;
      why.continuing_multiplier = 0.9f;
      if (event.to_frame >= 0) why.chosen = synthetic_frame_why(event.to_frame, weights, rng);
      why.continuing = synthetic_frame_why(event.from_frame + 1, weights, rng);
      why.continuing.cost = why.continuing.cost * why.continuing_multiplier + why.continuing_bias;
      r.why[a].push_back(std::move(why));
    }
  }
}

}  // namespace

Recording make_synthetic_recording(const SyntheticRecordingParams& params) {
  Recording r;
  Rng rng(params.seed);
  const std::size_t n = params.agents;
  r.title = "synthetic crowd: " + std::to_string(n) + " agents walking circles";
  r.sample_rate_hz = params.sample_rate_hz;
  r.agent_count = n;
  r.sample_count = static_cast<std::size_t>(std::floor(params.seconds * params.sample_rate_hz)) + 1;
  r.trajectory_times_s = {0.333f, 0.667f, 1.0f};
  set_skeleton(r);
  for (int32_t f = 0; f < kWalk.length; ++f) append_pose(r, kWalk, kWalk.first + f);
  for (int32_t f = 0; f < kRun.length; ++f) append_pose(r, kRun, kRun.first + f);
  const std::vector<Agent> agents = place_agents(n, rng);

  const std::size_t samples = r.sample_count * n;
  const std::size_t points = r.trajectory_points();
  r.root_x.resize(samples), r.root_z.resize(samples), r.facing.resize(samples), r.frame.resize(samples);
  r.desired_x.resize(samples * points), r.desired_z.resize(samples * points);
  r.matched_x.resize(samples * points), r.matched_z.resize(samples * points);
  r.goals.resize(n), r.searches.resize(n);
  for (std::size_t a = 0; a < n; ++a) simulate_agent(r, params, agents[a], a, rng);
  add_feet(r);
  add_detail(r, params);
  add_why(r, rng);
  return r;
}

}  // namespace mmvk::crowd
