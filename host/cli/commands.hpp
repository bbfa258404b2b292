// The mmvk subcommands. Each is declared once here and defined in its own
// file: `mmvk --help` lists them from these entries, and each command's own
// help starts with its usage line.
#pragma once

#include <span>
#include <string_view>

namespace mmvk::cli {

using Args = std::span<const std::string_view>;

struct Command {
  std::string_view name;       // "build"
  std::string_view arguments;  // the usage after "mmvk NAME", before [options]
  std::string_view summary;    // one line for `mmvk --help`
  // Takes the arguments after the subcommand name and returns the process
  // exit code; errors go to stderr. argv0: the program's path, to find data
  // installed beside it.
  int (*run)(Args args, const char* argv0);
};

extern const Command kBuildCommand;     // build_command.cpp
extern const Command kInspectCommand;   // inspect_command.cpp
extern const Command kExportCommand;    // export_command.cpp
extern const Command kQueryCommand;     // query_command.cpp
extern const Command kCrowdCommand;     // crowd_command.cpp
extern const Command kClustersCommand;  // clusters_command.cpp

}  // namespace mmvk::cli
