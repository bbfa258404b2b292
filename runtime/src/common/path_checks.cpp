// The up-front checks of a command's paths (mmvk/common/file_io.hpp:
// check_command_paths). Without them `mmvk export a.mmdb --features a.mmdb`
// replaced its own input and exited 0, and two outputs given one path kept
// only the last while the messages named both.
#include "mmvk/common/file_io.hpp"

namespace mmvk {

namespace {

std::string quoted(const NamedPath& p) { return p.name + " '" + p.path.string() + "'"; }

}  // namespace

Status check_command_paths(std::span<const NamedPath> paths) {
  for (const NamedPath& p : paths) {
    if (!p.output) continue;
    if (Status writable = check_writable(p.path); !writable) return make_error(p.name + ": " + writable.message());
  }
  for (std::size_t i = 0; i < paths.size(); ++i) {
    for (std::size_t j = i + 1; j < paths.size(); ++j) {
      const NamedPath& a = paths[i];
      const NamedPath& b = paths[j];
      if (!a.output && !b.output) continue;  // reading one file twice is harmless
      if ((a.output && is_stream_path(a.path)) || (b.output && is_stream_path(b.path))) continue;
      if (!same_file(a.path, b.path)) continue;
      const bool both = a.output && b.output;
      return make_error(quoted(a) + " and " + quoted(b) + " name the same file; " +
                        (both ? "one output would replace the other" : "the output would replace the input") +
                        " (give another path; nothing was written)");
    }
  }
  return {};
}

}  // namespace mmvk
