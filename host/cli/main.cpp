// mmvk: build, inspect, export and query motion matching databases.
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "commands.hpp"
#include "help_format.hpp"
#include "mmvk/database/database_io.hpp"

namespace {

constexpr const mmvk::cli::Command* kCommands[] = {
    &mmvk::cli::kBuildCommand, &mmvk::cli::kInspectCommand, &mmvk::cli::kExportCommand,
    &mmvk::cli::kQueryCommand, &mmvk::cli::kCrowdCommand,   &mmvk::cli::kClustersCommand};

std::string usage() {
  std::string text = "usage: mmvk <command> [options]\n       mmvk --version\n\ncommands:\n";
  for (const mmvk::cli::Command* command : kCommands) {
    text += mmvk::cli::help_entry(std::string(command->name) + " " + std::string(command->arguments),
                                  command->summary, 47, 100);
  }
  return text +
         "\n"
         "Run `mmvk <command> --help` for a command's options; `--` ends the options\n"
         "(`mmvk inspect -- -odd-name.mmdb`).\n"
         "\n"
         "Inputs are regular files (only query --queries may also be a pipe). A regular\n"
         "output is replaced atomically; a device or FIFO is written in place; an output\n"
         "that is an input or another output is refused (docs/files-and-limits.md).\n";
}

int dispatch(std::string_view name, mmvk::cli::Args rest, const char* program) {
  for (const mmvk::cli::Command* command : kCommands) {
    if (command->name == name) return command->run(rest, program);
  }
  std::fprintf(stderr, "mmvk: unknown command '%.*s'\n\n%s", int(name.size()), name.data(), usage().c_str());
  return 2;
}

// Results on stdout are what the user asked for: a full disk (> /dev/full)
// or any other failed write must not end with exit 0. The commands print
// through stdio, so one check of the stream's error flag and its final
// flush covers every printf and fputs before it.
int check_stdout(std::string_view command, int exit_code) {
  errno = 0;
  const bool failed = std::ferror(stdout) != 0;
  if (std::fclose(stdout) == 0 && !failed) return exit_code;
  std::fprintf(stderr, "mmvk %.*s: writing to standard output failed%s%s\n", int(command.size()), command.data(),
               errno != 0 ? ": " : "", errno != 0 ? std::strerror(errno) : "");
  return exit_code != 0 ? exit_code : 1;
}

}  // namespace

int main(int argc, char** argv) {
  // Past `ulimit -f`, the kernel's default for SIGXFSZ kills the process
  // mid-write and leaves the temp file; ignored, write() fails with EFBIG
  // ("File too large"), which every writer reports and cleans up after.
  std::signal(SIGXFSZ, SIG_IGN);
  std::vector<std::string_view> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    if (args.empty()) {
      std::fputs(usage().c_str(), stderr);
      return 2;
    }
    std::fputs(usage().c_str(), stdout);
    return check_stdout("help", 0);
  }
  if (args[0] == "--version" || args[0] == "-V") {
    // What a bug report needs: the program's version and the .mmdb format
    // it writes (and so which older mmvk can read its databases).
    std::printf("mmvk %s\ndatabase format: writes .mmdb version %u at most (the oldest that holds the database), "
                "reads versions 1 to %u\n",
                MMVK_VERSION, unsigned(mmvk::kDatabaseFormatVersion), unsigned(mmvk::kDatabaseFormatVersion));
    return check_stdout("--version", 0);
  }
  const std::string_view command = args[0];
  int exit_code = 1;
  try {
    exit_code = dispatch(command, mmvk::cli::Args(args.data() + 1, args.size() - 1), argv[0]);
  } catch (const std::bad_alloc&) {
    // The last resort behind the commands' own bounds (the crowd's memory
    // estimate, the size caps): a clean exit instead of an abort. Outputs are
    // written last and atomically, so none is left half-written.
    std::fprintf(stderr, "mmvk %.*s: out of memory (see docs/files-and-limits.md for the limits)\n",
                 int(command.size()), command.data());
    exit_code = 1;
  }
  return check_stdout(command, exit_code);
}
