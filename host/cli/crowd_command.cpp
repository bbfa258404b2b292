// mmvk crowd: thousands of motion-matched characters walking to their goals,
// one batched search per tick; prints what it used, writes a summary and the
// viewer page. The work is in host/crowd (run_crowd); this file parses the
// command line and reads the environment (the cache folder, the terminal).
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "crowd_backend.hpp"
#include "crowd_run.hpp"
#include "user_cache_dir.hpp"

namespace mmvk::cli {

namespace {

constexpr const char* kCrowdUsage =
    "usage: mmvk crowd [--data DIR|manifest.json|db.mmdb] [--agents N] [--seconds S] [--rate HZ]\n"
    "                  [--search-interval S] [--backend NAME] [--device N] [--seed N]\n"
    "                  [--scenario file.json] [--summary out.json] [--html out.html]\n"
    "\n"
    "Simulates a crowd on a ground plane: each character walks to its goals, steered\n"
    "(seek + separation on a uniform grid) at speeds measured in the database, and is\n"
    "animated by motion matching, all characters' searches batched into one per tick.\n"
    "\n"
    "  --data PATH           the motion: an .mmdb (built with animation), a manifest or a\n"
    "                        folder of BVH (built once and cached). Default: the CMU subject\n"
    "                        131 walks shipped with mmvk, cached in $XDG_CACHE_HOME/mmvk\n"
    "                        (or ~/.cache/mmvk)\n"
    "  --agents N            characters (default 1000, at most 10,000,000; with --scenario, its count)\n"
    "  --seconds S           simulated time (default 10; 1 to 10,000,000 ticks)\n"
    "  --rate HZ             simulation ticks per second (default 30; 1 to 1000)\n"
    "  --search-interval S   seconds between a character's regular searches (default 0.1; 0.001 to 3600)\n"
    "  --backend NAME        the search backend (default vulkan-brute, on the best device)\n"
    "  --device N            the Vulkan device index (default: the best one)\n"
    "  --seed N              the random scenario's seed (default 1)\n"
    "  --scenario FILE       starts, goals, speeds and tags from JSON (see host/crowd/scenario.hpp)\n"
    "  --summary FILE        write the run's figures as JSON\n"
    "  --html FILE           write the viewer: one self-contained page\n"
    "\n"
    "Inputs are regular files (a FIFO or device is refused); outputs are checked\n"
    "before the run, may be a FIFO or device (written in place) but never an input,\n"
    "and a run that would need more memory than this machine allows is refused\n"
    "with its estimate (docs/files-and-limits.md).\n";

}  // namespace

int run_crowd(Args args, const char* argv0) {
  const auto parsed = parse_args("crowd", args,
                                 {"--data", "--agents", "--seconds", "--rate", "--search-interval", "--backend",
                                  "--device", "--seed", "--scenario", "--summary", "--html"},
                                 {"--help", "-h"});
  if (!parsed) return 2;
  if (parsed->has("--help") || parsed->has("-h")) {
    std::fputs(kCrowdUsage, stdout);
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
               "mmvk crowd: trajectory error %.3f m at 1 s (median), foot sliding %.2f cm/s (the clips alone: %.2f), "
               "%.2f transitions "
               "per agent per second; chosen frames 0x%016llx\n",
               static_cast<unsigned long long>(s.ticks), s.wall_seconds, s.realtime_factor,
               static_cast<unsigned long long>(s.searches), static_cast<unsigned long long>(s.no_candidate),
               s.search_ms_p50, s.search_ms_p99, s.tick_ms_p50, s.tick_ms_p99, s.trajectory_error_m_1s,
               s.foot_sliding_cm_s, s.foot_sliding_database_cm_s, s.transitions_per_agent_s, static_cast<unsigned long long>(s.chosen_frames_hash));
  if (options.summary) {
    if (Status written = crowd::write_summary(s, *options.summary); !written) return fail(written.message());
    std::fprintf(stderr, "mmvk crowd: summary written to %s\n", options.summary->string().c_str());
  }
  if (options.html) {
    const auto absolute = std::filesystem::absolute(*options.html, ec);
    std::fprintf(stderr, "mmvk crowd: the viewer is at %s (%.1f MB): open it in a browser\n",
                 (ec ? *options.html : absolute).string().c_str(), double(s.html_bytes) / 1e6);
  }
  return 0;
}

}  // namespace mmvk::cli
