#include "crowd_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "clip_quality.hpp"
#include "crowd_backend.hpp"
#include "crowd_limits.hpp"
#include "crowd_paths.hpp"
#include "crowd_recorder.hpp"
#include "default_data.hpp"
#include "mmvk/hash.hpp"
#include "gait_plan.hpp"
#include "gait_speeds.hpp"
#include "mmvk/crowd_controller.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/query_builder.hpp"
#include "mmvk/trajectory.hpp"
#include "motion_meter.hpp"
#include "observed_search.hpp"
#include "progress_line.hpp"
#include "quality_meter.hpp"
#include "scenario.hpp"
#include "steering.hpp"
#include "trace.hpp"

#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

Status check_options(const CrowdOptions& o) {
  if (o.agents && *o.agents == 0) return make_error("--agents must be at least 1");
  if (!(o.seconds > 0.0) || !std::isfinite(o.seconds)) return make_error("--seconds must be a positive number");
  if (!(o.rate_hz > 0.0) || !std::isfinite(o.rate_hz)) return make_error("--rate must be a positive number (Hz)");
  if (!(o.search_interval_s > 0.0) || !std::isfinite(o.search_interval_s)) {
    return make_error("--search-interval must be a positive number (seconds)");
  }
  if (o.continuing_bias && !std::isfinite(*o.continuing_bias)) return make_error("--continuing-bias must be finite");
  if (o.continuing_multiplier && !(std::isfinite(*o.continuing_multiplier) && *o.continuing_multiplier >= 0.0f)) {
    return make_error("--continuing-multiplier must be finite and >= 0");
  }
  if (o.correction_half_life && !(std::isfinite(*o.correction_half_life) && *o.correction_half_life > 0.0f)) {
    return make_error("--correction-half-life must be a positive number (seconds)");
  }
  return check_time_options(o);
}

Result<OpenedDatabase> open_crowd_database(const DataChoice& data, const CrowdOptions& options, std::FILE* log) {
  auto say = [log](const std::string& line) {
    if (log) std::fprintf(log, "mmvk crowd: %s\n", line.c_str());
  };
  return open_database(data.source, options.cache_dir, say);
}

Result<Scenario> make_scenario(const CrowdOptions& options, bool can_run) {
  if (!options.scenario) {
    RandomScenarioOptions random;
    random.agents = options.agents.value_or(1000);
    random.seed = options.seed;
    if (!can_run) random.run_fraction = 0.0f;  // data without a run gets no runners
    return make_random_scenario(random);
  }
  MMVK_ASSIGN_OR_RETURN(Scenario scenario, load_scenario(*options.scenario));
  if (options.agents && *options.agents != scenario.agents.size()) {
    return make_error(scenario.source + ": defines " + std::to_string(scenario.agents.size()) +
                      " agents, but --agents asks for " + std::to_string(*options.agents) +
                      " (leave --agents out with --scenario)");
  }
  return scenario;
}

// Tags by name, per agent, into the controller's query parameters.
Status apply_tags(const Scenario& scenario, const Database& database, std::span<QueryParams> params) {
  for (std::size_t a = 0; a < scenario.agents.size(); ++a) {
    const AgentPlan& plan = scenario.agents[a];
    const std::string where = scenario.source + ": agents[" + std::to_string(a) + "].";
    Result<TagMask> require = database.tag_mask(plan.require_tags);
    if (!require) return make_error(where + "require_tags: " + require.message());
    Result<TagMask> exclude = database.tag_mask(plan.exclude_tags);
    if (!exclude) return make_error(where + "exclude_tags: " + exclude.message());
    params[a].require_all = *require;
    params[a].exclude_any = *exclude;
  }
  return {};
}

// Added to the cost of the frame a character would play anyway: a jump must
// win by this much. Queries measure the pose the character shows, which
// (blended) lies further from every stored row than the row of the frame
// it plays did, so the bias that holds jumps to the same rate is larger.
// Measured with clusters, 200 characters, 10 s, seed 1, 30 Hz (trajectory
// error at 1 s, foot sliding before IK, transitions per character per s):
//   CMU 131:  -1: 0.046 m, 19.3 cm/s, 1.70;  -2: 0.050 m, 19.5, 1.27;  -3: 0.051 m, 20.2, 1.09
//   Bandai:   -1: 0.042 m, 24.9 cm/s, 2.50;  -2: 0.045 m, 24.8, 1.90
// (queries copied from the played frame's row, bias -1: CMU 0.055 m, 18.5,
// 1.32; Bandai 0.045 m, 25.8, 2.05). With foot IK and 1,000 characters for
// 20 s, Bandai jumped 2.04 times a second at -2, 1.86 at -2.5 and 1.74 at
// -3, following its paths 0.046, 0.047 and 0.048 m off (CMU: 1.30, 1.23,
// 1.17; 0.049, 0.050, 0.050 m). Feature costs are sums of squared z-scores,
// so the scale carries over to other databases.
constexpr float kContinuingBias = -2.5f;

// The root correction's half-life (ControllerParams::correction_half_life,
// 0.2 s by default). Foot locking holds planted feet against the correction,
// so the crowd can pull characters onto their paths harder than the
// animation alone could hide. 1,000 characters x 20 s (trajectory error at
// 1 s, sliding after IK, transitions per second):
//   CMU 131, 60 Hz:  0.2 s: 0.051 m, 0.38 cm/s, 1.23;  0.15 s: 0.042, 0.34, 1.18;  0.1 s: 0.031, 0.31, 1.11
//   Bandai, 60 Hz:   0.2 s: 0.048 m, 0.95 cm/s, 1.93;  0.15 s: 0.043, 0.89, 1.88;  0.1 s: 0.036, 0.87, 1.87
// 0.1 s clamps the legs' reach more often (7.1% of foot-ticks on CMU against
// 5.4%), so 0.15 s, for data of the user's; a shipped set carries its own
// (default_data.cpp).
constexpr float kCorrectionHalfLife = 0.15f;

// The 1 s horizon of the trajectory error, as the controller would predict it.
constexpr float kErrorHorizon[1] = {1.0f};

// --weights on every character's query options; errors name --weights.
Status apply_weights(const CrowdOptions& options, const Database& database, std::span<QueryParams> params) {
  if (options.weights.empty()) return {};
  QueryParams weighted;
  for (const auto& [channel, weight] : options.weights) {
    if (Status set = set_channel_weight(database.schema(), weighted, channel, weight); !set) {
      return make_error("--weights: " + set.message());
    }
  }
  for (QueryParams& p : params) p.channel_weights = weighted.channel_weights;
  return {};
}

// The spacing of the pose acceleration samples: the database's frame
// interval in ticks (motion_meter.hpp).
std::uint32_t acceleration_step(double rate_hz, double fps) {
  return std::uint32_t(std::clamp(std::lround(rate_hz / fps), 1L, 16L));
}

}  // namespace

Result<CrowdSummary> run_crowd(const CrowdOptions& options, std::FILE* log) {
  MMVK_TRY(check_options(options));
  MMVK_ASSIGN_OR_RETURN(const DataChoice data, choose_data(options.data, options.executable));
  // Before the database, which may take a while to build: every output
  // writable, none of them an input or another output (crowd_paths.hpp).
  MMVK_TRY(check_crowd_paths(options, data.source));
  MMVK_ASSIGN_OR_RETURN(OpenedDatabase opened, open_crowd_database(data, options, log));
  const Database& db = opened.database;
  const std::string& db_name = data.label;
  if (!db.animation()) {
    return make_error(db_name + ": " + missing_animation_error("mmvk crowd").message);
  }
  Result<GaitSpeeds> speeds = measure_gait_speeds(db);
  if (!speeds) return make_error(db_name + ": " + speeds.message());
  MMVK_TRY(check_crowd_memory(options, db, nullptr));
  MMVK_ASSIGN_OR_RETURN(Scenario scenario, make_scenario(options, speeds->has_run));
  MMVK_TRY(check_crowd_memory(options, db, &scenario));
  MMVK_TRY(resolve_gaits(scenario, *speeds));
  const auto agents = std::uint32_t(scenario.agents.size());

  ControllerParams params;
  params.search_interval = float(options.search_interval_s);
  params.continuing_bias = options.continuing_bias.value_or(kContinuingBias);
  params.correction_half_life =
      options.correction_half_life.value_or(data.correction_half_life.value_or(kCorrectionHalfLife));
  params.continuing_multiplier = options.continuing_multiplier.value_or(params.continuing_multiplier);
  params.exclusion_window = options.exclusion_window.value_or(params.exclusion_window);
  params.foot_ik.enabled = options.foot_ik;
  Result<CrowdController> created = CrowdController::create(db, agents, params);
  if (!created) return make_error(db_name + ": " + created.message());
  CrowdController controller = std::move(created.value());
  MMVK_TRY(apply_tags(scenario, db, controller.query_params()));
  MMVK_TRY(apply_weights(options, db, controller.query_params()));
  for (std::uint32_t b = 0; b < agents; ++b) {
    const AgentPlan& plan = scenario.agents[b];
    const float yaw = std::atan2(plan.goals[0][0] - plan.start[0], plan.goals[0][1] - plan.start[1]);
    MMVK_TRY(controller.place(b, glm::vec3(plan.start[0], 0.0f, plan.start[1]), yaw));
  }

  ThreadPool pool(0);
  MMVK_ASSIGN_OR_RETURN(CrowdSearch search,
                        make_crowd_search(options.backend, options.device, db, agents, pool, options.cache_dir));
  if (log) {
    char run[48] = "no run: every character walks";
    if (speeds->has_run) std::snprintf(run, sizeof(run), "run %.2f m/s", double(speeds->run_mps));
    std::fprintf(log, "mmvk crowd: %u agents for %.1f s at %.0f Hz on %s (%u frames; walk %.2f m/s, %s)\n", agents,
                 options.seconds, options.rate_hz, db_name.c_str(), db.frame_count(), speeds->walk_mps, run);
    if (!speeds->has_run) std::fprintf(log, "mmvk crowd: note: no run in the data: %s\n", speeds->no_run_reason.c_str());
    std::fprintf(log, "mmvk crowd: backend %s on %s\n", std::string(search.backend->name()).c_str(),
                 search.device.c_str());
    if (!search.pipeline_cache_note.empty()) {
      std::fprintf(log, "mmvk crowd: note: %s\n", search.pipeline_cache_note.c_str());
    }
  }

  const float dt = float(1.0 / options.rate_hz);
  const auto ticks = std::uint64_t(std::llround(options.seconds * options.rate_hz));
  const AnimationData& animation = controller.animation();
  const std::size_t joints = animation.joint_count();
  std::optional<TraceWriter> trace;
  if (options.trace) {
    const TraceLayout layout{ticks, options.trace_agents, std::uint32_t(joints), options.rate_hz};
    Result<TraceWriter> writer =
        TraceWriter::create(*options.trace, layout, animation.skeleton, animation.contact_joints, agents);
    if (!writer) return writer.error();
    trace.emplace(std::move(writer.value()));
  }
  Steering steering(scenario, *speeds);
  ObservedSearch observed(*search.deferred, agents);
  QualityMeter meter(agents, dt);
  // The clips first: their planted toe height is the crowd's floor.
  const ClipQuality clips = measure_clip_quality(db, pool);
  MotionMeterParams motion_params;
  motion_params.legs = find_leg_joints(animation);
  motion_params.planted_height = clips.planted_height;
  motion_params.dt = dt;
  motion_params.acceleration_step = acceleration_step(options.rate_hz, db.fps());
  // Three half-lives: the inertialization's blend has done 90% of its work.
  motion_params.jump_window_s = 3.0 * params.inertialization_half_life;
  MotionMeter motion(agents, joints, motion_params);
  std::unique_ptr<CrowdRecorder> recorder;
  if (options.html) {
    const auto per_sample = std::uint32_t(std::max(1.0, std::round(options.rate_hz / 10.0)));
    // Short enough for the page's header: "1000 agents · locomotion-normal · vulkan-brute-force on llvmpipe".
    const std::string device = search.device.substr(0, search.device.find(" ("));
    recorder = std::make_unique<CrowdRecorder>(
        controller, scenario,
        std::to_string(agents) + " agents \u00b7 " + data.short_label + " \u00b7 " + std::string(search.backend->name()) + " on " + device,
        dt, per_sample);
  }
  ProgressLine progress(options.progress ? log : nullptr, double(ticks) * dt,
                        std::size_t(std::max(1.0, options.rate_hz)));

  // Per tick, [N] each; sized once.
  std::vector<float> x(agents), z(agents), vx(agents), vz(agents), desired_xz(2 * agents), root_xz(2 * agents);
  std::vector<glm::vec3> desired(agents), world(agents * joints), animated(agents * joints);
  std::vector<std::uint32_t> searched_before, searched_now, frames_before(agents);
  std::vector<std::uint8_t> kinds_before(agents, 0);  // controller.searched() of the tick before
  searched_before.reserve(agents), searched_now.reserve(agents);
  glm::vec3 horizon_pos[1];
  float horizon_yaw[1];

  std::vector<double> search_ms, tick_ms;
  search_ms.reserve(ticks), tick_ms.reserve(ticks);
  Hasher chosen;
  std::uint64_t searches = 0;
  const auto run_start = Clock::now();
  for (std::uint64_t t = 0; t < ticks; ++t) {
    const auto tick_start = Clock::now();
    const auto roots = controller.root_positions();
    for (std::uint32_t b = 0; b < agents; ++b) x[b] = roots[b].x, z[b] = roots[b].z;
    steering.update(x, z, vx, vz);
    for (std::uint32_t b = 0; b < agents; ++b) desired[b] = glm::vec3(vx[b], 0.0f, vz[b]);
    observed.begin_tick();
    MMVK_TRY(controller.tick(dt, CrowdInput{desired, {}}, observed, pool));
    tick_ms.push_back(ms_since(tick_start));
    search_ms.push_back(observed.blocked_seconds() * 1e3);

    // The chosen frames, in order: every applied match of every tick.
    const auto matches = observed.collected_matches();
    chosen.add_u32(std::uint32_t(t));
    chosen.add_u32(std::uint32_t(matches.size()));
    for (const Match& m : matches) chosen.add_u32(m.frame);
    searches += controller.last_tick().searches;

    // Quality: where the controller wants each character 1 s from now, where
    // it is, and its feet.
    const auto sim = controller.simulation();
    const auto roots_now = controller.root_positions();
    for (std::uint32_t b = 0; b < agents; ++b) {
      predict_trajectory(sim[b], desired[b], yaw_of_velocity(desired[b], sim[b].yaw), params.spring, kErrorHorizon,
                         horizon_pos, horizon_yaw);
      desired_xz[2 * b] = horizon_pos[0].x, desired_xz[2 * b + 1] = horizon_pos[0].z;
      root_xz[2 * b] = roots_now[b].x, root_xz[2 * b + 1] = roots_now[b].z;
    }
    meter.record_trajectory(desired_xz, root_xz);
    meter.add_transitions(controller.last_tick().jumps);
    meter.end_tick();
    // The pose as displayed (after foot IK) and as animated (before).
    controller.world_positions(world, pool);
    controller.animated_world_positions(animated, pool);
    motion.record({world, animated, controller.contacts(), controller.foot_locked(), controller.ik_reach_clamped(),
                   controller.jumped()});
    if (trace) trace->record(world, controller.contacts(), controller.foot_locked());

    if (recorder) recorder->record_tick(t, matches, searched_before, kinds_before, frames_before, world);
    searched_now.clear();
    const auto kinds = controller.searched();
    for (std::uint32_t b = 0; b < agents; ++b) {
      if (kinds[b] != 0) searched_now.push_back(b);
    }
    searched_before.swap(searched_now);
    std::copy(kinds.begin(), kinds.end(), kinds_before.begin());
    const auto frames = controller.frames();
    std::copy(frames.begin(), frames.end(), frames_before.begin());
    progress.tick(double(t + 1) * dt, controller.last_tick().searches, search_ms.back());
  }
  const double wall = std::chrono::duration<double>(Clock::now() - run_start).count();
  progress.finish();

  CrowdSummary s;
  s.agents = agents;
  s.ticks = ticks;
  s.seconds = double(ticks) / options.rate_hz;
  s.rate_hz = options.rate_hz;
  s.search_interval_s = options.search_interval_s;
  s.seed = options.seed;
  s.scenario = scenario.source;
  s.database = opened.path.empty() ? db_name : opened.path.string();
  s.database_frames = db.frame_count();
  s.walk_mps = speeds->walk_mps;
  s.run_mps = speeds->has_run ? speeds->run_mps : std::nan("");  // null in the JSON
  s.runners = count_runners(scenario);
  if (!speeds->has_run) s.notes.push_back("run_mps is null: the data has no run (" + speeds->no_run_reason + ")");
  s.backend = std::string(search.backend->name());
  s.device = search.device;
  s.searches = searches;
  s.forced_searches = controller.totals().forced;
  s.no_candidate = controller.totals().no_candidate;
  s.queries_per_tick = ticks ? double(searches) / double(ticks) : 0.0;
  s.search_ms_p50 = percentile(search_ms, 0.5);
  s.search_ms_p99 = percentile(search_ms, 0.99);
  s.tick_ms_p50 = percentile(tick_ms, 0.5);
  s.tick_ms_p99 = percentile(tick_ms, 0.99);
  s.wall_seconds = wall;
  s.realtime_factor = wall > 0.0 ? s.seconds / wall : 0.0;
  s.trajectory_error_m_1s = meter.trajectory_error_m_median();
  s.foot_ik = options.foot_ik;
  s.correction_half_life_s = std::round(double(params.correction_half_life) * 1e6) / 1e6;  // 0.07, not 0.0700000003
  s.motion = motion.figures();
  s.clips = clips.figures;
  s.planted_height_m = clips.planted_height;
  s.transitions_per_agent_s = meter.transitions_per_agent_s();
  s.goals_reached = steering.goals_reached();
  s.chosen_frames_hash = chosen.digest();
  if (Status saved = save_crowd_pipeline_cache(search); !saved && log) {
    std::fprintf(log, "mmvk crowd: note: the Vulkan pipeline cache was not saved: %s\n", saved.message().c_str());
  }

  if (trace) {
    MMVK_TRY(trace->finish());
    s.trace = options.trace->string();
  }
  if (options.html) {
    Recording recording = recorder->finish(pool);
    MMVK_ASSIGN_OR_RETURN(const std::size_t bytes, write_viewer_html(*options.html, recording));
    s.html = options.html->string();
    s.html_bytes = bytes;
  }
  return s;
}

}  // namespace mmvk::crowd
