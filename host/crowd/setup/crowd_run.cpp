#include "setup/crowd_run.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <utility>

#include "setup/crowd_limits.hpp"
#include "steering/crowd_paths.hpp"
#include "setup/crowd_session.hpp"
#include "setup/default_data.hpp"
#include "output/pose_export.hpp"
#include "output/progress_line.hpp"
#include "steering/scenario.hpp"
#include "output/trace.hpp"

namespace mmvk::crowd {

namespace {

Result<OpenedDatabase> open_crowd_database(const DataChoice& data, const CrowdOptions& options, std::FILE* log) {
  auto say = [log](const std::string& line) {
    if (log) std::fprintf(log, "mmvk crowd: %s\n", line.c_str());
  };
  return open_database(data.source, options.cache_dir, say);
}

// The session's options: the command's settings, its scenario file, what it
// writes and where its data came from.
Result<CrowdSessionOptions> session_options(const CrowdOptions& options, const DataChoice& data) {
  CrowdSessionOptions session;
  static_cast<CrowdSettings&>(session) = options;
  session.names = SettingNames::Flags;
  if (options.scenario) {
    MMVK_ASSIGN_OR_RETURN(Scenario scenario, load_scenario(*options.scenario));
    session.scenario = std::move(scenario);
  }
  session.outputs.html = options.html.has_value();
  session.outputs.trace_agents = options.trace ? options.trace_agents : 0;
  session.outputs.export_agents =
      options.bvh || options.gltf ? (options.export_agents > 0 ? options.export_agents : kDefaultExportAgents) : 0;
  session.record = options.html.has_value();
  session.data_label = data.short_label;
  session.data_source = data.label;
  session.cache_dir = options.cache_dir;
  return session;
}

void log_start(std::FILE* log, const CrowdOptions& options, const std::string& db_name, const CrowdSession& crowd) {
  if (!log) return;
  const GaitSpeeds& speeds = crowd.speeds();
  const CrowdSearch& search = crowd.search();
  char run[48] = "no run: every character walks";
  if (speeds.has_run) std::snprintf(run, sizeof(run), "run %.2f m/s", double(speeds.run_mps));
  const std::string backend = std::string(search.backend->name()) +
                              (search.choice.empty() ? std::string() : " (" + search.choice + ")");
  std::fprintf(log, "mmvk crowd: %u agents for %.1f s at %.0f Hz on %s (%u frames; walk %.2f m/s, %s); backend %s\n",
               crowd.agents(), options.seconds, options.rate_hz, db_name.c_str(), crowd.controller().database().frame_count(),
               speeds.walk_mps, run, backend.c_str());
  // Why the data has no run is in the summary's notes, printed at the end.
  std::fprintf(log, "mmvk crowd: backend %s on %s\n", std::string(search.backend->name()).c_str(),
               search.device.c_str());
  if (!search.driver_cache_note.empty()) std::fprintf(log, "mmvk crowd: note: %s\n", search.driver_cache_note.c_str());
  if (!search.pipeline_cache_note.empty()) {
    std::fprintf(log, "mmvk crowd: note: %s\n", search.pipeline_cache_note.c_str());
  }
}

Result<std::optional<TraceWriter>> open_trace(const CrowdOptions& options, const CrowdSession& crowd) {
  if (!options.trace) return std::optional<TraceWriter>();
  const AnimationData& animation = crowd.controller().animation();
  const TraceLayout layout{tick_count(options), options.trace_agents, std::uint32_t(animation.joint_count()),
                           options.rate_hz};
  Result<TraceWriter> writer =
      TraceWriter::create(*options.trace, layout, animation.skeleton, animation.contact_joints, crowd.agents());
  if (!writer) return writer.error();
  return std::optional<TraceWriter>(std::move(writer.value()));
}

// The loop: the crowd's own steering for every tick, the trace, the pose
// export and the progress line after each.
Status run_ticks(CrowdSession& crowd, const CrowdOptions& options, TraceWriter* trace, PoseExport* poses,
                 std::FILE* log) {
  const std::uint64_t ticks = tick_count(options);
  ProgressLine progress(options.progress ? log : nullptr, double(ticks) * crowd.dt(),
                        std::size_t(std::max(1.0, options.rate_hz)));
  for (std::uint64_t t = 0; t < ticks; ++t) {
    MMVK_TRY(crowd.step());
    if (trace) trace->record(crowd.world_positions(), crowd.controller().contacts(), crowd.controller().foot_locked());
    if (poses) MMVK_TRY(poses->record(crowd.controller()));
    progress.tick(double(t + 1) * crowd.dt(), crowd.controller().last_tick().searches, crowd.last_search_ms());
  }
  progress.finish();
  return {};
}

// The outputs after the loop: the pipeline cache, the trace, the exports and the page.
Status finish_outputs(CrowdSession& crowd, const CrowdOptions& options, std::optional<TraceWriter>& trace,
                      const std::optional<PoseExport>& poses, std::FILE* log, CrowdSummary& s) {
  if (Status saved = save_crowd_pipeline_cache(crowd.search()); !saved && log) {
    std::fprintf(log, "mmvk crowd: note: the Vulkan pipeline cache was not saved: %s\n", saved.message().c_str());
  }
  if (trace) {
    MMVK_TRY(trace->finish());
    s.trace = options.trace->string();
  }
  if (poses) MMVK_TRY(poses->finish());
  if (options.html) {
    MMVK_ASSIGN_OR_RETURN(const std::size_t bytes, crowd.write_html(*options.html));
    s.html = options.html->string();
    s.html_bytes = bytes;
  }
  return {};
}

}  // namespace

Result<CrowdSummary> run_crowd(const CrowdOptions& options, std::FILE* log) {
  // Setup: the settings, the data, the session.
  MMVK_TRY(validate(options, SettingNames::Flags));
  MMVK_ASSIGN_OR_RETURN(const DataChoice data, choose_data(options.data, options.executable));
  // Before the database, which may take a while to build: every output
  // writable, none of them an input or another output (crowd_paths.hpp).
  MMVK_TRY(check_crowd_paths(options, data.source));
  MMVK_ASSIGN_OR_RETURN(OpenedDatabase opened, open_crowd_database(data, options, log));
  MMVK_TRY(check_crowd_paths_with_database(options, data.source, opened.path));
  MMVK_ASSIGN_OR_RETURN(const CrowdSessionOptions session, session_options(options, data));
  MMVK_ASSIGN_OR_RETURN(std::unique_ptr<CrowdSession> crowd, CrowdSession::create(opened.database, session));
  log_start(log, options, data.label, *crowd);

  // The loop, then the summary and the outputs.
  MMVK_ASSIGN_OR_RETURN(std::optional<TraceWriter> trace, open_trace(options, *crowd));
  MMVK_ASSIGN_OR_RETURN(std::optional<PoseExport> poses,
                        PoseExport::open(options, crowd->controller().animation(), crowd->agents(), tick_count(options)));
  MMVK_TRY(run_ticks(*crowd, options, trace ? &*trace : nullptr, poses ? &*poses : nullptr, log));
  CrowdSummary s = crowd->summary();
  s.database = opened.path.empty() ? data.label : opened.path.string();
  MMVK_TRY(finish_outputs(*crowd, options, trace, poses, log, s));
  return s;
}

}  // namespace mmvk::crowd
