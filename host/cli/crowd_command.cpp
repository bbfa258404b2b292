// mmvk crowd: thousands of motion-matched characters walking to their goals,
// one batched search per tick; prints what it used, writes a summary and the
// viewer page. The work is in host/crowd (run_crowd); this file parses the
// command line and reads the environment (the cache folder, the terminal).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "crowd_backend.hpp"
#include "crowd_run.hpp"
#include "default_data.hpp"
#include "user_cache_dir.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kCrowdUsage =
    "usage: mmvk crowd [--data NAME|DIR|manifest.json|db.mmdb] [--agents N] [--seconds S] [--rate HZ]\n"
    "                  [--search-interval S] [--backend NAME] [--device N] [--seed N]\n"
    "                  [--scenario file.json] [--summary out.json] [--html out.html]\n"
    "                  [--foot-ik on|off] [--continuing-bias B] [--continuing-multiplier M]\n"
    "                  [--exclusion-window N] [--weights CHANNEL=W,...] [--correction-half-life S]\n"
    "                  [--trace FILE] [--trace-agents M]\n"
    "\n"
    "Simulates a crowd on a ground plane: each character walks to its goals, steered\n"
    "(seek + separation on a uniform grid) at speeds measured in the database, and is\n"
    "animated by motion matching, all characters' searches batched into one per tick.\n"
    "\n"
    "  --data NAME|PATH      the motion: a shipped set by name (below), an .mmdb (built with\n"
    "                        animation), a manifest or a folder of BVH (built once and cached\n"
    "                        in $XDG_CACHE_HOME/mmvk or ~/.cache/mmvk). Default: cmu-walks\n"
    "  --agents N            characters (default 1000, at most 10,000,000; with --scenario, its count)\n"
    "  --seconds S           simulated time (default 10; 1 to 10,000,000 ticks)\n"
    "  --rate HZ             simulation ticks per second (default 30; 1 to 1000: poses are\n"
    "                        interpolated between database frames)\n"
    "  --search-interval S   seconds between a character's regular searches (default 0.1; 0.001 to 3600)\n"
    "  --backend NAME        the search backend (default vulkan-brute, on the best device)\n"
    "  --device N            the Vulkan device index (default: the best one)\n"
    "  --seed N              the random scenario's seed (default 1)\n"
    "  --scenario FILE       starts, goals, speeds and tags from JSON (see host/crowd/scenario.hpp)\n"
    "  --summary FILE        write the run's figures as JSON\n"
    "  --html FILE           write the viewer: one self-contained page\n"
    "  --foot-ik on|off      lock planted feet where they touched down, legs solved by\n"
    "                        two-bone IK (default on)\n"
    "  --continuing-bias B   added to the cost of the frame a character would play anyway\n"
    "                        (default -2.5: a jump must win by 2.5)\n"
    "  --continuing-multiplier M  multiplies that frame's cost first (finite, >= 0; default 1)\n"
    "  --exclusion-window N  frames within N of that frame in its clip are no candidates\n"
    "                        (default 0)\n"
    "  --weights CHANNEL=W,...  reweigh schema channels for every search (W >= 0)\n"
    "  --correction-half-life S  half-life of the pull of each character's animated root\n"
    "                        towards its simulated position (default: the shipped set's, below;\n"
    "                        other data 0.15 s; shorter holds the characters closer to their\n"
    "                        paths, with more root motion that the animation did not make)\n"
    "  --trace FILE          write the displayed world joint positions of the first\n"
    "                        --trace-agents characters every tick: float32 x, y, z per\n"
    "                        joint, [ticks x agents x joints], and FILE.json beside it\n"
    "                        (joint names, parents, tick rate, contacts, foot locks);\n"
    "                        held in memory until the run ends, at most 512 MiB\n"
    "  --trace-agents M      characters in the trace (default 1)\n"
    "\n"
    "Inputs are regular files (a FIFO or device is refused); outputs are checked\n"
    "before the run, may be a FIFO or device (written in place) but never an input,\n"
    "and a run that would need more memory than this machine allows is refused\n"
    "with its estimate (docs/files-and-limits.md).\n";

// One entry per shipped set, its description wrapped under the usage's
// option descriptions (column 22, at most 88 wide).
std::string shipped_data_help() {
  constexpr std::size_t kIndent = 22;
  constexpr std::size_t kWidth = 88;
  std::string out;
  for (const crowd::ShippedData& data : crowd::shipped_data()) {
    // Appending, not "  " + std::string(...): GCC 12 at -O3 warns (-Wrestrict,
    // a known false positive) on the latter.
    std::string line("  ");
    line.append(data.name);
    line.resize(std::max(kIndent, line.size() + 1), ' ');
    bool fresh = true;  // no word on this line yet
    char settings[64];
    std::snprintf(settings, sizeof(settings), ". Crowd settings: --correction-half-life %g",
                  double(data.correction_half_life));
    const std::string text = std::string(data.description) + settings;
    std::string_view rest = text;
    while (!rest.empty()) {
      const std::size_t space = rest.find(' ');
      const std::string_view word = rest.substr(0, space);
      rest = space == std::string_view::npos ? std::string_view() : rest.substr(space + 1);
      if (!fresh && line.size() + 1 + word.size() > kWidth) {
        out += line + "\n";
        line.assign(kIndent, ' ');
        fresh = true;
      }
      if (!fresh) line += ' ';
      line.append(word);
      fresh = false;
    }
    out += line + "\n";
  }
  return out;
}

}  // namespace

int run_crowd(Args args, const char* argv0) {
  const auto parsed = parse_args("crowd", args,
                                 {"--data", "--agents", "--seconds", "--rate", "--search-interval", "--backend",
                                  "--device", "--seed", "--scenario", "--summary", "--html", "--foot-ik",
                                  "--continuing-bias", "--continuing-multiplier", "--exclusion-window", "--weights",
                                  "--correction-half-life", "--trace", "--trace-agents"},
                                 {"--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(kCrowdUsage, stdout);
    std::printf("\nshipped motion sets (--data NAME; the first is the default):\n%s", shipped_data_help().c_str());
    std::printf("\nbackends:\n%s", crowd::crowd_backend_help().c_str());
    return 0;
  }
  if (!parsed->positional.empty()) {
    std::fprintf(stderr, "mmvk crowd: unexpected argument '%s' (the data goes after --data)\n\n%s",
                 parsed->positional[0].c_str(), kCrowdUsage);
    return 2;
  }
  auto fail = [](const std::string& message) { return report_error("crowd", message, 1); };
  crowd::CrowdOptions options;
  if (const auto v = parsed->value("--data")) options.data = *v;
  if (const auto v = parsed->value("--agents")) {
    Result<std::uint32_t> agents = parse_u32("--agents", *v, 1, 10'000'000);
    if (!agents) return fail(agents.message());
    options.agents = *agents;
  }
  for (auto [option, target] : {std::pair{"--seconds", &options.seconds}, std::pair{"--rate", &options.rate_hz},
                                std::pair{"--search-interval", &options.search_interval_s}}) {
    if (const auto v = parsed->value(option)) {
      Result<double> value = parse_positive(option, *v);
      if (!value) return fail(value.message());
      *target = *value;
    }
  }
  if (const auto v = parsed->value("--backend")) options.backend = *v;
  if (const auto v = parsed->value("--device")) {
    Result<std::uint32_t> device = parse_u32("--device", *v);
    if (!device) return fail(device.message());
    options.device = *device;
  }
  if (const auto v = parsed->value("--seed")) {
    Result<std::uint64_t> seed = parse_integer("--seed", *v);
    if (!seed) return fail(seed.message());
    options.seed = *seed;
  }
  if (const auto v = parsed->value("--scenario")) options.scenario = *v;
  if (const auto v = parsed->value("--summary")) options.summary = *v;
  if (const auto v = parsed->value("--html")) options.html = *v;
  if (const auto v = parsed->value("--foot-ik")) {
    if (*v != "on" && *v != "off") return fail("--foot-ik expects on or off, got '" + *v + "'");
    options.foot_ik = *v == "on";
  }
  if (const auto v = parsed->value("--continuing-bias")) {
    Result<float> bias = parse_float("--continuing-bias", *v);
    if (!bias) return fail(bias.message());
    options.continuing_bias = *bias;
  }
  if (const auto v = parsed->value("--continuing-multiplier")) {
    Result<float> multiplier = parse_float("--continuing-multiplier", *v);
    if (!multiplier) return fail(multiplier.message());
    if (*multiplier < 0.0f) return fail("--continuing-multiplier must be >= 0, got '" + *v + "'");
    options.continuing_multiplier = *multiplier;
  }
  if (const auto v = parsed->value("--exclusion-window")) {
    Result<std::uint32_t> window = parse_u32("--exclusion-window", *v);
    if (!window) return fail(window.message());
    options.exclusion_window = *window;
  }
  if (const auto v = parsed->value("--weights")) {
    Result<std::vector<std::pair<std::string, float>>> weights = parse_weight_list("--weights", *v);
    if (!weights) return fail(weights.message());
    options.weights = std::move(*weights);
  }
  if (const auto v = parsed->value("--correction-half-life")) {
    Result<double> half_life = parse_positive("--correction-half-life", *v);
    if (!half_life) return fail(half_life.message());
    options.correction_half_life = float(*half_life);
  }
  if (const auto v = parsed->value("--trace")) options.trace = *v;
  if (const auto v = parsed->value("--trace-agents")) {
    if (!options.trace) return fail("--trace-agents needs --trace FILE");
    Result<std::uint32_t> traced = parse_u32("--trace-agents", *v, 1);
    if (!traced) return fail(traced.message());
    options.trace_agents = *traced;
  }
  std::error_code ec;
  if (argv0) options.executable = std::filesystem::canonical("/proc/self/exe", ec);
  if (ec || options.executable.empty()) options.executable = argv0 ? argv0 : "";
  options.cache_dir = user_cache_directory().value_or(std::filesystem::path{});
  options.progress = stderr_is_terminal();

  Result<crowd::CrowdSummary> summary = crowd::run_crowd(options, stderr);
  if (!summary) return fail(summary.message());
  const crowd::CrowdSummary& s = *summary;
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
  if (options.summary) {
    if (Status written = crowd::write_summary(s, *options.summary); !written) return fail(written.message());
    std::fprintf(stderr, "mmvk crowd: summary written to %s\n", options.summary->string().c_str());
  }
  if (options.trace) std::fprintf(stderr, "mmvk crowd: trace written to %s\n", options.trace->string().c_str());
  if (options.html) {
    const auto absolute = std::filesystem::absolute(*options.html, ec);
    std::fprintf(stderr, "mmvk crowd: the viewer is at %s (%.1f MB): open it in a browser\n",
                 (ec ? *options.html : absolute).string().c_str(), double(s.html_bytes) / 1e6);
  }
  return 0;
}

}  // namespace mmvk::cli
