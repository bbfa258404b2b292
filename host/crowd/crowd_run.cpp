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
#include "crowd_defaults.hpp"
#include "crowd_limits.hpp"
#include "crowd_paths.hpp"
#include "default_data.hpp"
#include "gait_plan.hpp"
#include "gait_speeds.hpp"
#include "mmvk/crowd_controller.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/query_builder.hpp"
#include "observed_search.hpp"
#include "observed_tick.hpp"
#include "progress_line.hpp"
#include "quality_meter.hpp"
#include "run_summary.hpp"
#include "scenario.hpp"
#include "steering.hpp"
#include "tick_observers.hpp"
#include "trace.hpp"

#include "viewer/viewer_html.hpp"

namespace mmvk::crowd {

namespace {

using Clock = std::chrono::steady_clock;


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
    random.agents = options.agents.value_or(kDefaultAgents);
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

// The motion checked for a crowd: it has animation and walks.
Result<GaitSpeeds> check_motion(const Database& db, const std::string& db_name) {
  if (!db.animation()) {
    return make_error(db_name + ": " + missing_animation_error("mmvk crowd").message);
  }
  Result<GaitSpeeds> speeds = measure_gait_speeds(db);
  if (!speeds) return make_error(db_name + ": " + speeds.message());
  return speeds;
}

// The scenario, its gaits resolved, once the run is known to fit in memory.
Result<Scenario> plan_scenario(const CrowdOptions& options, const Database& db, const GaitSpeeds& speeds) {
  MMVK_TRY(check_crowd_memory(options, db, nullptr));
  MMVK_ASSIGN_OR_RETURN(Scenario scenario, make_scenario(options, speeds.has_run));
  MMVK_TRY(check_crowd_memory(options, db, &scenario));
  MMVK_TRY(resolve_gaits(scenario, speeds));
  return scenario;
}

// The flags' settings, else the shipped set's, else the crowd's defaults.
ControllerParams controller_params(const CrowdOptions& options, const DataChoice& data) {
  ControllerParams params;
  params.search_interval = float(options.search_interval_s);
  params.continuing_bias = options.continuing_bias.value_or(kContinuingBias);
  params.correction_half_life =
      options.correction_half_life.value_or(data.correction_half_life.value_or(kCorrectionHalfLife));
  params.continuing_multiplier = options.continuing_multiplier.value_or(params.continuing_multiplier);
  params.exclusion_window = options.exclusion_window.value_or(params.exclusion_window);
  params.foot_ik.enabled = options.foot_ik;
  return params;
}

// The controller with the scenario's tags and --weights, every character at
// its start facing its first goal.
Result<CrowdController> make_controller(const Database& db, const std::string& db_name, const Scenario& scenario,
                                        const CrowdOptions& options, const ControllerParams& params) {
  const auto agents = std::uint32_t(scenario.agents.size());
  Result<CrowdController> created = CrowdController::create(db, agents, params);
  if (!created) return make_error(db_name + ": " + created.message());
  CrowdController controller = std::move(created.value());
  MMVK_TRY(apply_plan_tags(scenario, db, controller.query_params()));
  MMVK_TRY(apply_weights(options, db, controller.query_params()));
  for (std::uint32_t b = 0; b < agents; ++b) {
    const AgentPlan& plan = scenario.agents[b];
    const float yaw = std::atan2(plan.goals[0][0] - plan.start[0], plan.goals[0][1] - plan.start[1]);
    MMVK_TRY(controller.place(b, glm::vec3(plan.start[0], 0.0f, plan.start[1]), yaw));
  }
  return controller;
}

void log_start(std::FILE* log, const CrowdOptions& options, const std::string& db_name, const Database& db,
               const GaitSpeeds& speeds, const CrowdSearch& search, std::uint32_t agents) {
  if (!log) return;
  char run[48] = "no run: every character walks";
  if (speeds.has_run) std::snprintf(run, sizeof(run), "run %.2f m/s", double(speeds.run_mps));
  std::fprintf(log, "mmvk crowd: %u agents for %.1f s at %.0f Hz on %s (%u frames; walk %.2f m/s, %s)\n", agents,
               options.seconds, options.rate_hz, db_name.c_str(), db.frame_count(), speeds.walk_mps, run);
  if (!speeds.has_run) std::fprintf(log, "mmvk crowd: note: no run in the data: %s\n", speeds.no_run_reason.c_str());
  std::fprintf(log, "mmvk crowd: backend %s on %s\n", std::string(search.backend->name()).c_str(),
               search.device.c_str());
  if (!search.driver_cache_note.empty()) std::fprintf(log, "mmvk crowd: note: %s\n", search.driver_cache_note.c_str());
  if (!search.pipeline_cache_note.empty()) {
    std::fprintf(log, "mmvk crowd: note: %s\n", search.pipeline_cache_note.c_str());
  }
}

Result<std::optional<TraceWriter>> open_trace(const CrowdOptions& options, const AnimationData& animation,
                                              std::uint64_t ticks, std::uint32_t agents) {
  if (!options.trace) return std::optional<TraceWriter>();
  const TraceLayout layout{ticks, options.trace_agents, std::uint32_t(animation.joint_count()), options.rate_hz};
  Result<TraceWriter> writer =
      TraceWriter::create(*options.trace, layout, animation.skeleton, animation.contact_joints, agents);
  if (!writer) return writer.error();
  return std::optional<TraceWriter>(std::move(writer.value()));
}

// The viewer's recording for --html: one sample every tenth of a second.
std::unique_ptr<RecordingObserver> make_recording(const CrowdOptions& options, const CrowdController& controller,
                                                  const Scenario& scenario, const DataChoice& data,
                                                  const CrowdSearch& search, float dt) {
  if (!options.html) return nullptr;
  const auto per_sample = std::uint32_t(std::max(1.0, std::round(options.rate_hz / 10.0)));
  // Short enough for the page's header: "1000 agents · locomotion-normal · vulkan-brute-force on llvmpipe".
  const std::string device = search.device.substr(0, search.device.find(" ("));
  return std::make_unique<RecordingObserver>(
      controller, scenario,
      std::to_string(controller.size()) + " agents \u00b7 " + data.short_label + " \u00b7 " +
          std::string(search.backend->name()) + " on " + device,
      dt, per_sample);
}

// The simulation loop: steering, the controller's tick, then every observer.
class TickLoop {
 public:
  TickLoop(CrowdController& controller, Steering& steering, ObservedSearch& observed, ThreadPool& pool,
           QualityObserver& quality, RecordingObserver* recording, TraceWriter* trace, float dt)
      : controller_(controller), steering_(steering), observed_(observed), pool_(pool), quality_(quality),
        recording_(recording), trace_(trace), dt_(dt), x_(controller.size()), z_(controller.size()),
        vx_(controller.size()), vz_(controller.size()), desired_(controller.size()),
        world_(std::size_t{controller.size()} * controller.animation().joint_count()) {}

  // Runs `ticks` ticks; the per-tick timings are kept for the summary.
  Status run(std::uint64_t ticks, ProgressLine& progress) {
    figures_.reserve(ticks);
    const auto run_start = Clock::now();
    for (std::uint64_t t = 0; t < ticks; ++t) {
      MMVK_TRY(step(t));
      progress.tick(double(t + 1) * dt_, controller_.last_tick().searches, figures_.last_search_ms());
    }
    wall_seconds_ = std::chrono::duration<double>(Clock::now() - run_start).count();
    return {};
  }

  // The loop's own figures: searches, their timings and the chosen frames.
  void summarize(CrowdSummary& s) const { figures_.summarize(s, wall_seconds_); }

 private:
  Status step(std::uint64_t t) {
    const auto tick_start = Clock::now();
    const auto roots = controller_.root_positions();
    for (std::uint32_t b = 0; b < controller_.size(); ++b) x_[b] = roots[b].x, z_[b] = roots[b].z;
    steering_.update(x_, z_, vx_, vz_, &pool_);
    for (std::uint32_t b = 0; b < controller_.size(); ++b) desired_[b] = glm::vec3(vx_[b], 0.0f, vz_[b]);
    MMVK_TRY(observed_tick(controller_, observed_, pool_, t, dt_, CrowdInput{desired_, {}}, tick_start, world_,
                           {figures_, quality_, recording_})
                 .status());
    if (trace_) trace_->record(world_, controller_.contacts(), controller_.foot_locked());
    return {};
  }

  CrowdController& controller_;
  Steering& steering_;
  ObservedSearch& observed_;
  ThreadPool& pool_;
  QualityObserver& quality_;
  RecordingObserver* recording_;
  TraceWriter* trace_;
  const float dt_;
  // Per tick, [agents] or [agents x joints]; sized once.
  std::vector<float> x_, z_, vx_, vz_;
  std::vector<glm::vec3> desired_, world_;
  TickFigures figures_;
  double wall_seconds_ = 0.0;
};


}  // namespace

Result<CrowdSummary> run_crowd(const CrowdOptions& options, std::FILE* log) {
  // Setup: the data, the scenario, the controller and the search.
  MMVK_TRY(check_options(options));
  MMVK_ASSIGN_OR_RETURN(const DataChoice data, choose_data(options.data, options.executable));
  // Before the database, which may take a while to build: every output
  // writable, none of them an input or another output (crowd_paths.hpp).
  MMVK_TRY(check_crowd_paths(options, data.source));
  MMVK_ASSIGN_OR_RETURN(OpenedDatabase opened, open_crowd_database(data, options, log));
  MMVK_TRY(check_crowd_paths_with_database(options, data.source, opened.path));
  const Database& db = opened.database;
  MMVK_ASSIGN_OR_RETURN(const GaitSpeeds speeds, check_motion(db, data.label));
  MMVK_ASSIGN_OR_RETURN(Scenario scenario, plan_scenario(options, db, speeds));
  const ControllerParams params = controller_params(options, data);
  MMVK_ASSIGN_OR_RETURN(CrowdController controller, make_controller(db, data.label, scenario, options, params));
  const std::uint32_t agents = controller.size();
  ThreadPool pool(0);
  MMVK_ASSIGN_OR_RETURN(CrowdSearch search,
                        make_crowd_search(options.backend, options.device, db, agents, pool, options.cache_dir));
  log_start(log, options, data.label, db, speeds, search, agents);

  // The observers, then the loop.
  const float dt = float(1.0 / options.rate_hz);
  const auto ticks = std::uint64_t(std::llround(options.seconds * options.rate_hz));
  MMVK_ASSIGN_OR_RETURN(std::optional<TraceWriter> trace, open_trace(options, controller.animation(), ticks, agents));
  Steering steering(scenario, speeds);
  ObservedSearch observed(*search.deferred, agents);
  const ClipQuality clips = measure_clip_quality(db, pool);
  QualityObserver quality(controller, params, clips, dt, options.rate_hz, db.fps());
  const std::unique_ptr<RecordingObserver> recording =
      make_recording(options, controller, scenario, data, search, dt);
  ProgressLine progress(options.progress ? log : nullptr, double(ticks) * dt,
                        std::size_t(std::max(1.0, options.rate_hz)));
  TickLoop loop(controller, steering, observed, pool, quality, recording.get(), trace ? &*trace : nullptr, dt);
  MMVK_TRY(loop.run(ticks, progress));
  progress.finish();

  // Summary: the figures, then the outputs.
  CrowdSummary s =
      summarize_run({db, scenario, speeds, search, controller, params, quality, clips, steering, ticks, options.rate_hz,
                     options.search_interval_s, options.seed, options.foot_ik});
  s.database = opened.path.empty() ? data.label : opened.path.string();
  loop.summarize(s);
  if (Status saved = save_crowd_pipeline_cache(search); !saved && log) {
    std::fprintf(log, "mmvk crowd: note: the Vulkan pipeline cache was not saved: %s\n", saved.message().c_str());
  }
  if (trace) {
    MMVK_TRY(trace->finish());
    s.trace = options.trace->string();
  }
  if (recording) {
    MMVK_ASSIGN_OR_RETURN(const std::size_t bytes, write_viewer_html(*options.html, recording->finish(pool)));
    s.html = options.html->string();
    s.html_bytes = bytes;
  }
  return s;
}

}  // namespace mmvk::crowd
