// Placeholder until the command is implemented; replaced by its owner.
#include <cstdio>

#include "commands.hpp"

namespace mmvk::cli {

int run_inspect(Args) {
  std::fputs("mmvk inspect: not implemented yet\n", stderr);
  return 1;
}

}  // namespace mmvk::cli
