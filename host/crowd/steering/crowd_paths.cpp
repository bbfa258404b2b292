#include "steering/crowd_paths.hpp"

#include <system_error>

#include "mmvk/database/database_io.hpp"
#include "mmvk/database/manifest.hpp"
#include "output/pose_export.hpp"
#include "output/trace.hpp"

namespace mmvk::crowd {

std::vector<NamedPath> crowd_paths(const CrowdOptions& options, const std::filesystem::path& data_source) {
  std::vector<NamedPath> paths;
  const std::string data = options.data ? "--data" : "the default data";
  paths.push_back({data, data_source, false});
  // A manifest or a folder: the files its build reads are inputs too. A
  // manifest that does not load is reported by the run itself.
  std::error_code ec;
  if (data_source.extension() != ".mmdb" && !has_database_magic(data_source) &&
      std::filesystem::exists(data_source, ec)) {
    if (Result<Manifest> manifest = load_manifest_or_directory(data_source); manifest) {
      for (const std::filesystem::path& file : manifest_input_files(*manifest)) {
        paths.push_back({"a clip of " + data, file, false});
      }
    }
  }
  if (options.scenario) paths.push_back({"--scenario", *options.scenario, false});
  if (options.summary) paths.push_back({"--summary", *options.summary, true});
  if (options.html) paths.push_back({"--html", *options.html, true});
  if (options.trace) {
    paths.push_back({"--trace", *options.trace, true});
    paths.push_back({"the trace's sidecar (--trace + .json)", trace_sidecar_path(*options.trace), true});
  }
  if (options.gltf) paths.push_back({"--gltf", *options.gltf, true});
  return paths;
}

// As export refuses it: the sidecar beside a device or FIFO would be a new
// file in /dev (as root, --trace /dev/null made /dev/null.json).
Status check_crowd_paths(const CrowdOptions& options, const std::filesystem::path& data_source) {
  if (options.trace && is_stream_path(*options.trace)) {
    return make_error("--trace " + options.trace->string() + " is a device or FIFO: its sidecar would be " +
                      trace_sidecar_path(*options.trace).string() + " beside it; write the trace to a file");
  }
  MMVK_TRY(check_pose_export_paths(options));
  return check_command_paths(crowd_paths(options, data_source));
}

Status check_crowd_paths_with_database(const CrowdOptions& options, const std::filesystem::path& data_source,
                                       const std::filesystem::path& database) {
  if (database.empty()) return {};
  std::vector<NamedPath> paths = crowd_paths(options, data_source);
  paths.push_back({"the cache entry", database, false});
  return check_command_paths(paths);
}

}  // namespace mmvk::crowd
