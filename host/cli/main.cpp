// mmvk: build, inspect, export and query motion matching databases.
#include <cstdio>
#include <string_view>
#include <vector>

#include "commands.hpp"

namespace {

constexpr const char* kUsage =
    "usage: mmvk <command> [options]\n"
    "\n"
    "commands:\n"
    "  build <manifest.json | bvh-dir> -o db.mmdb   build a database from BVH motion capture\n"
    "  inspect db.mmdb                              clips, frames, channel statistics and tags\n"
    "  export db.mmdb --features out.f32            the normalized feature matrix + JSON sidecar\n"
    "  query db.mmdb --queries q.f32 ...            batched search, one result line per query\n"
    "  crowd [--agents N] [--html out.html] ...     a motion-matched crowd, its figures and a viewer page\n"
    "  clusters db.mmdb -o table.mmkc               train and save the cluster tables (query --clusters)\n"
    "\n"
    "Run `mmvk <command> --help` for a command's options.\n";

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string_view> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string_view command = args[0];
  const mmvk::cli::Args rest(args.data() + 1, args.size() - 1);
  if (command == "build") return mmvk::cli::run_build(rest);
  if (command == "inspect") return mmvk::cli::run_inspect(rest);
  if (command == "export") return mmvk::cli::run_export(rest);
  if (command == "query") return mmvk::cli::run_query(rest);
  if (command == "crowd") return mmvk::cli::run_crowd(rest, argv[0]);
  if (command == "clusters") return mmvk::cli::run_clusters(rest);
  std::fprintf(stderr, "mmvk: unknown command '%.*s'\n\n%s", int(command.size()), command.data(), kUsage);
  return 2;
}
