#include "setup/cache_entry.hpp"

#include <filesystem>
#include <string>

namespace mmvk::crowd {

Status validate_cache_entry(const Database& database, const Manifest& manifest) {
  if (!database.animation()) {
    return make_error("it has no animation: " + no_animation_explanation(database.no_animation_reason()));
  }
  if (database.dims() != manifest.schema.dims()) {
    return make_error("it has " + std::to_string(database.dims()) + " feature dims, the manifest's schema " +
                      std::to_string(manifest.schema.dims()));
  }
  // The clips as the manifest lists them (mirrored copies aside), compared
  // by name and file name: the folder part of a source depends on the
  // working directory the entry was built from.
  std::size_t next = 0;
  for (const Clip& clip : database.clips()) {
    if (clip.mirrored) continue;
    if (next >= manifest.clips.size()) return make_error("it has more clips than the manifest");
    const ManifestClip& expected = manifest.clips[next];
    const std::string file = std::filesystem::path(clip.source).filename().string();
    const std::string expected_file = expected.file.filename().string();
    if (clip.name != expected.name || file != expected_file) {
      return make_error("its clip " + std::to_string(next) + " is '" + clip.name + "' from " + file +
                        ", the manifest's is '" + expected.name + "' from " + expected_file);
    }
    ++next;
  }
  if (next != manifest.clips.size()) {
    return make_error("it has " + std::to_string(next) + " clips, the manifest " +
                      std::to_string(manifest.clips.size()));
  }
  return {};
}

}  // namespace mmvk::crowd
