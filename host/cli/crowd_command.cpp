// mmvk crowd: thousands of motion-matched characters walking to their goals,
// one batched search per tick; prints what it used, writes a summary and the
// viewer page. The work is in host/crowd (run_crowd); this file parses the
// command line and reads the environment (the cache folder, the terminal).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>

#include "cli_args.hpp"
#include "command_line.hpp"
#include "commands.hpp"
#include "help_format.hpp"
#include "mmvk/common/number_text.hpp"
#include "backends/crowd_backend.hpp"
#include "setup/crowd_run.hpp"
#include "setup/crowd_defaults.hpp"
#include "setup/crowd_limits.hpp"
#include "setup/data_settings.hpp"
#include "setup/default_data.hpp"
#include "setup/detail_agents.hpp"
#include "mmvk/database/manifest.hpp"
#include "user_cache_dir.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kCrowdDescription =
    "Simulates a crowd on a ground plane: each character walks to its goals, steered (seek + separation on a "
    "uniform grid) at speeds measured in the database, and is animated by motion matching, all characters' "
    "searches batched into one per tick.";

constexpr const char* kCrowdFiles =
    "Inputs are regular files (a FIFO or device is refused); outputs are checked\n"
    "before the run, may be a FIFO or device (written in place) but never an input,\n"
    "and a run that would need more memory than this machine allows is refused\n"
    "with its estimate (docs/files-and-limits.md).\n";

// ". Crowd settings: --correction-half-life 0.07": what the set's manifest
// holds (its "crowd" block), or nothing when its files are missing.
std::string shipped_settings(const crowd::ShippedData& data) {
  std::error_code ec;
  const Result<crowd::DataChoice> choice =
      crowd::choose_data(std::filesystem::path(data.name), std::filesystem::canonical("/proc/self/exe", ec));
  if (!choice) return "";
  const Result<Manifest> manifest = load_manifest(choice->source);
  if (!manifest) return "";
  const Result<crowd::DataSettings> settings = crowd::parse_data_settings(manifest->crowd, choice->source.string());
  if (!settings) return "";
  const std::string text = crowd::describe_data_settings(*settings);
  return text.empty() ? "" : ". Crowd settings: " + text;
}

// The sections after the options: files, the shipped motion sets (one entry
// each, wrapped like the options) and the backends.
std::string crowd_footer() {
  std::string out = kCrowdFiles;
  out += "\nshipped motion sets (--data NAME; the first is the default):\n";
  for (const crowd::ShippedData& data : crowd::shipped_data()) {
    out += help_entry(data.name,
                      std::string(data.description) + ". Can do: " + std::string(data.capabilities) +
                          " (measured gait tags; mmvk inspect has the counts)" + shipped_settings(data),
                      22);
  }
  return out + "\nbackends:\n" + crowd::crowd_backend_help();
}

std::string default_data_name() {
  const auto shipped = crowd::shipped_data();
  return shipped.empty() ? std::string("none") : std::string(shipped.front().name);
}

// The motion, the crowd and its clock, the search backend. The defaults in
// the help are those `options` holds before the parse.
void declare_run(CommandLine& cli, crowd::CrowdOptions& options) {
  cli.text("--data", options.data, "NAME|PATH",
           "the motion: a shipped set by name (below), an .mmdb (built with animation), a manifest or a folder of "
           "BVH (built once and cached in $XDG_CACHE_HOME/mmvk or ~/.cache/mmvk). Default: " +
               default_data_name());
  // The bounds are checked by the crowd's validate() (crowd_settings.hpp) on the values given.
  cli.integer("--agents", options.agents, "N",
              "characters (default " + std::to_string(crowd::kDefaultAgents) + ", at most " +
                  thousands(crowd::kMaxAgents) + "; with --scenario, its count)",
              0, std::numeric_limits<std::uint64_t>::max());
  cli.positive("--seconds", options.seconds, "S",
               "simulated time (default " + number_text(options.seconds) + "; 1 to " + thousands(crowd::kMaxTicks) +
                   " ticks)");
  cli.positive("--rate", options.rate_hz, "HZ",
               "simulation ticks per second (default " + number_text(options.rate_hz) + "; " +
                   number_text(crowd::kMinRateHz) + " to " + number_text(crowd::kMaxRateHz) +
                   ": poses are interpolated between database frames)");
  cli.positive("--search-interval", options.search_interval_s, "S",
               "seconds between a character's regular searches (default " + number_text(options.search_interval_s) +
                   "; " + number_text(crowd::kMinSearchIntervalS) + " to " + number_text(crowd::kMaxSearchIntervalS) +
                   ")");
  cli.text("--backend", options.backend, "NAME",
           "the search backend (default " + options.backend +
               ": a Vulkan backend on a GPU, else the fastest CPU backend; below)");
  cli.integer("--device", options.device, "N", "the Vulkan device index (default: the best one)");
  cli.integer("--seed", options.seed, "N", "the random scenario's seed (default " + std::to_string(options.seed) + ")", 0,
              std::numeric_limits<std::uint64_t>::max());
  cli.finite("--wait-at-goals", options.wait_at_goals_s, "S",
             "seconds each character of the random scenario stands at each goal before it leaves for the next "
             "(default " + number_text(options.wait_at_goals_s) + "; 0 to " + number_text(crowd::kMaxGoalWaitS) +
                 "; a --scenario file sets its own \"wait_s\")");
  cli.text("--scenario", options.scenario, "FILE",
           "starts, goals, speeds and tags from JSON (see host/crowd/steering/scenario.hpp)");
  cli.text("--summary", options.summary, "FILE", "write the run's figures as JSON");
  cli.text("--html", options.html, "FILE", "write the viewer: one self-contained page");
  cli.value("--detail-agents", options.detail_agents, "SPEC",
            "the characters the viewer keeps in detail, their whole pose after every tick and every search "
            "explained (the others at 10 Hz): N, the first N (default " +
                std::to_string(crowd::kDefaultDetailAgents) +
                ", or the crowd when smaller; 0: none), or indices and ranges such as 0-9,42,100-104 (one "
                "character k alone: k-k); each adds about 50 KB to the page per 20 s at 30 Hz",
            [](const std::string& text) { return crowd::parse_detail_agents(text, "--detail-agents"); });
}

// A switch's parser: `flag` on|off.
auto on_off(const char* flag) {
  return [flag](const std::string& text) -> Result<bool> {
    if (text != "on" && text != "off") return make_error(std::string(flag) + " expects on or off, got '" + text + "'");
    return text == "on";
  };
}

// How the characters move: foot locking, speed from the animation and the
// search's cost terms.
void declare_motion(CommandLine& cli, crowd::CrowdOptions& options) {
  cli.value("--foot-ik", options.foot_ik, "on|off",
            "lock planted feet where they touched down, legs solved by two-bone IK (default " +
                std::string(options.foot_ik ? "on" : "off") + ")",
            on_off("--foot-ik"));
  cli.value("--speed-from-animation", options.speed_from_animation, "on|off",
            "play each clip faster or slower and scale its stride toward the commanded speed, and hold the root "
            "correction to half the animation's own speed (default " +
                std::string(options.speed_from_animation ? "on" : "off") + "; off: the data's own speeds)",
            on_off("--speed-from-animation"));
  cli.finite("--continuing-bias", options.continuing_bias, "B",
             "added to the cost of the frame a character would play anyway (default " +
                 number_text(crowd::kContinuingBias) + ": a jump must win by " + number_text(-crowd::kContinuingBias) +
                 ")");
  cli.value("--continuing-multiplier", options.continuing_multiplier, "M",
            "multiplies that frame's cost first (finite, >= 0; default 1)", [](const std::string& text) -> Result<float> {
              MMVK_ASSIGN_OR_RETURN(const float multiplier, parse_float("--continuing-multiplier", text));
              if (multiplier < 0.0f) return make_error("--continuing-multiplier must be >= 0, got '" + text + "'");
              return multiplier;
            });
  cli.integer("--exclusion-window", options.exclusion_window, "N",
              "frames within N of that frame in its clip are no candidates (default 0)");
  cli.value("--weights", options.weights, "CHANNEL=W,...", "reweigh schema channels for every search (W >= 0)",
            [](const std::string& text) { return parse_weight_list("--weights", text); });
  cli.positive("--correction-half-life", options.correction_half_life, "S",
               "half-life of the pull of each character's animated root towards its simulated position (default: "
               "the data's, its manifest's \"crowd\" block; else " + number_text(crowd::kCorrectionHalfLife) +
                   " s; shorter holds the characters closer to their paths, with "
               "more root motion that the animation did not make)");
}

void declare_trace(CommandLine& cli, crowd::CrowdOptions& options) {
  cli.text("--trace", options.trace, "FILE",
           "write the displayed world joint positions of the first --trace-agents characters every tick: float32 x, "
           "y, z per joint, [ticks x agents x joints], and FILE.json beside it (joint names, parents, tick rate, "
           "contacts, foot locks); held in memory until the run ends, at most 512 MiB");
  cli.integer("--trace-agents", options.trace_agents, "M", "characters in the trace (default " + std::to_string(options.trace_agents) + ")", 1);
}

void declare_export(CommandLine& cli, crowd::CrowdOptions& options) {
  cli.text("--bvh", options.bvh, "DIR",
           "write the displayed pose (after foot IK) of the first --export-agents characters as one BVH each, "
           "DIR/agent_0000.bvh ..., at the tick rate on the database's skeleton (centimetres, ZXY degrees)");
  cli.text("--gltf", options.gltf, "FILE.glb",
           "write the same characters into one glTF 2.0 binary: each a skin over its joint nodes, animated at the "
           "tick rate; the poses of both are held in memory until the run ends, at most 512 MiB");
  cli.integer("--export-agents", options.export_agents, "M",
              "characters in --bvh and --gltf, the first of the crowd (default " +
                  std::to_string(crowd::kDefaultExportAgents) + ", or the crowd when smaller)", 1);
}

// Returns the exit code when the crowd must not run (help, bad options).
std::optional<int> parse_crowd_args(Args args, crowd::CrowdOptions& options) {
  CommandLine cli(kCrowdCommand, kCrowdDescription);
  // A bad value here is a failed run (1), as the crowd host's own checks are.
  cli.value_error_exit(1);
  declare_run(cli, options);
  declare_motion(cli, options);
  declare_trace(cli, options);
  declare_export(cli, options);
  cli.footer(crowd_footer);
  cli.stray_argument_hint("the data goes after --data");
  if (const std::optional<int> exit_code = cli.parse(args)) return exit_code;
  if (cli.given("--trace-agents") && !options.trace) {
    return report_error("crowd", "--trace-agents needs --trace FILE", 1);
  }
  if (cli.given("--detail-agents") && !options.html) {
    return report_error("crowd", "--detail-agents needs --html FILE", 1);
  }
  if (cli.given("--export-agents") && !options.bvh && !options.gltf) {
    return report_error("crowd", "--export-agents needs --bvh DIR or --gltf FILE.glb", 1);
  }
  return std::nullopt;
}

// What the crowd reads from the environment: the program's folder (shipped
// data installed beside it), the cache folder, the terminal.
void add_environment(crowd::CrowdOptions& options, const char* argv0) {
  std::error_code ec;
  if (argv0) options.executable = std::filesystem::canonical("/proc/self/exe", ec);
  if (ec || options.executable.empty()) options.executable = argv0 ? argv0 : "";
  options.cache_dir = user_cache_directory().value_or(std::filesystem::path{});
  options.progress = stderr_is_terminal();
}

void print_figures(const crowd::CrowdSummary& s) {
  std::fprintf(stderr,
               "mmvk crowd: %llu ticks in %.2f s (%.1fx real time): %llu searches (%llu without a candidate), "
               "search %.2f / %.2f ms, tick %.2f / %.2f ms (p50 / p99)\n"
               "mmvk crowd: trajectory error %.3f m at 1 s (median), "
               "%.2f transitions "
               "per agent per second; chosen frames 0x%016llx\n",
               static_cast<unsigned long long>(s.ticks), s.wall_seconds, s.realtime_factor,
               static_cast<unsigned long long>(s.searches), static_cast<unsigned long long>(s.no_candidate),
               s.search_ms_p50, s.search_ms_p99, s.tick_ms_p50, s.tick_ms_p99, s.trajectory_error_m_1s,
               s.transitions_per_agent_s, static_cast<unsigned long long>(s.chosen_frames_hash));
  std::fputs(crowd::describe_motion(s).c_str(), stderr);
  // What the data could not do for this run, as the summary's notes say it.
  for (const std::string& note : s.notes) std::fprintf(stderr, "mmvk crowd: note: %s\n", note.c_str());
}

// Writes the summary and says where the outputs are.
Status finish_outputs(const crowd::CrowdOptions& options, const crowd::CrowdSummary& s) {
  if (options.summary) {
    MMVK_TRY(crowd::write_summary(s, *options.summary));
    std::fprintf(stderr, "mmvk crowd: summary written to %s\n", options.summary->string().c_str());
  }
  if (options.trace) std::fprintf(stderr, "mmvk crowd: trace written to %s\n", options.trace->string().c_str());
  if (options.bvh) std::fprintf(stderr, "mmvk crowd: BVH files written to %s\n", options.bvh->string().c_str());
  if (options.gltf) std::fprintf(stderr, "mmvk crowd: glTF written to %s\n", options.gltf->string().c_str());
  if (options.html) {
    std::error_code ec;
    const auto absolute = std::filesystem::absolute(*options.html, ec);
    std::fprintf(stderr, "mmvk crowd: the viewer is at %s (%.1f MB): open it in a browser\n",
                 (ec ? *options.html : absolute).string().c_str(), double(s.html_bytes) / 1e6);
  }
  return {};
}

int run_crowd(Args args, const char* argv0) {
  crowd::CrowdOptions options;
  if (const std::optional<int> exit_code = parse_crowd_args(args, options)) return *exit_code;
  add_environment(options, argv0);
  Result<crowd::CrowdSummary> summary = crowd::run_crowd(options, stderr);
  if (!summary) return report_error("crowd", summary.message(), 1);
  print_figures(*summary);
  if (Status finished = finish_outputs(options, *summary); !finished) return report_error("crowd", finished.message(), 1);
  return 0;
}

}  // namespace

const Command kCrowdCommand{"crowd", "", "a motion-matched crowd, its figures and a viewer page", run_crowd};

}  // namespace mmvk::cli
