// The files a manifest's build reads (mmvk/database/manifest.hpp).
#include "mmvk/features/features.hpp"
#include "mmvk/database/manifest.hpp"

namespace mmvk {

std::vector<std::filesystem::path> manifest_input_files(const Manifest& manifest) {
  std::vector<std::filesystem::path> files;
  for (const ManifestClip& clip : manifest.clips) {
    files.push_back(clip.file);
    for (const FeatureChannel& channel : manifest.schema.channels) {
      if (reads_sidecar(channel.kind)) files.push_back(custom_sidecar_path(clip.file, channel));
    }
  }
  return files;
}

}  // namespace mmvk
