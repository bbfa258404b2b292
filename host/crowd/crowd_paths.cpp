#include "crowd_paths.hpp"

#include <system_error>

#include "mmvk/manifest.hpp"

namespace mmvk::crowd {

std::vector<NamedPath> crowd_paths(const CrowdOptions& options) {
  std::vector<NamedPath> paths;
  if (options.data) {
    paths.push_back({"--data", *options.data, false});
    // A manifest or a folder: the files its build reads are inputs too. A
    // manifest that does not load is reported by the run itself.
    std::error_code ec;
    if (options.data->extension() != ".mmdb" && std::filesystem::exists(*options.data, ec)) {
      if (Result<Manifest> manifest = load_manifest_or_directory(*options.data); manifest) {
        for (const std::filesystem::path& file : manifest_input_files(*manifest)) {
          paths.push_back({"a clip of --data", file, false});
        }
      }
    }
  }
  if (options.scenario) paths.push_back({"--scenario", *options.scenario, false});
  if (options.summary) paths.push_back({"--summary", *options.summary, true});
  if (options.html) paths.push_back({"--html", *options.html, true});
  return paths;
}

Status check_crowd_paths(const CrowdOptions& options) { return check_command_paths(crowd_paths(options)); }

}  // namespace mmvk::crowd
