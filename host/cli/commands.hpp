// The mmvk subcommands. Each takes its arguments after the subcommand name
// and returns the process exit code; errors go to stderr.
#pragma once

#include <span>
#include <string_view>

namespace mmvk::cli {

using Args = std::span<const std::string_view>;

int run_build(Args args);    // build_command.cpp
int run_inspect(Args args);  // inspect_command.cpp
int run_export(Args args);   // export_command.cpp
int run_query(Args args);    // query_command.cpp
// argv0: the program's path, to find data installed beside it.
int run_crowd(Args args, const char* argv0);  // crowd_command.cpp
int run_clusters(Args args);  // clusters_command.cpp

}  // namespace mmvk::cli
