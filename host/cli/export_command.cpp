// Placeholder until the command is implemented; replaced by its owner.
#include <cstdio>

#include "commands.hpp"

namespace mmvk::cli {

int run_export(Args) {
  std::fputs("mmvk export: not implemented yet\n", stderr);
  return 1;
}

}  // namespace mmvk::cli
