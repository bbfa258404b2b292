#include "bench_data.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/manifest.hpp"
#include "mmvk/thread_pool.hpp"

namespace mmvk::bench {

namespace fs = std::filesystem;

namespace {

fs::path data_dir() {
  const char* from_env = std::getenv("MMVK_DATA");
  return from_env && *from_env ? fs::path(from_env) : fs::path(MMVK_DEFAULT_DATA_DIR);
}

fs::path work_dir() { return MMVK_BENCH_WORK_DIR; }

// Unpacks the Bandai volume archives into the build tree once (never into the
// shared data folder); a marker file records a completed unpack.
bool unpack_volume(const fs::path& target) {
  const fs::path marker = target / ".unpacked";
  if (fs::exists(marker)) return true;
  fs::create_directories(target);
  const fs::path archives = data_dir() / "bandai-namco-nc" / "volume";
  if (!fs::is_directory(archives)) {
    std::fprintf(stderr, "bench: %s not found (set MMVK_DATA)\n", archives.c_str());
    return false;
  }
  for (const fs::directory_entry& entry : fs::directory_iterator(archives)) {
    if (entry.path().extension() != ".xz") continue;
    std::fprintf(stderr, "bench: unpacking %s\n", entry.path().filename().c_str());
    const std::string command = "tar -xJf '" + entry.path().string() + "' -C '" + target.string() + "'";
    if (std::system(command.c_str()) != 0) {
      std::fprintf(stderr, "bench: '%s' failed\n", command.c_str());
      return false;
    }
  }
  std::FILE* done = std::fopen(marker.c_str(), "w");
  if (done) std::fclose(done);
  return true;
}

// Every BVH folder of the set, in a fixed order.
Result<Manifest> manifest_for(DataSet set) {
  const fs::path locomotion = data_dir() / "bandai-namco-nc" / "locomotion-normal";
  Result<Manifest> manifest = manifest_from_directory(locomotion);
  if (!manifest || set == DataSet::Locomotion) return manifest;
  const fs::path volume = work_dir() / "volume";
  if (!unpack_volume(volume)) return make_error("bench: the volume archives could not be unpacked");
  for (const char* dataset : {"Bandai-Namco-Research-Motiondataset-1", "Bandai-Namco-Research-Motiondataset-2"}) {
    Result<Manifest> part = manifest_from_directory(volume / dataset / "data");
    if (!part) return part.error();
    manifest->clips.insert(manifest->clips.end(), part->clips.begin(), part->clips.end());
  }
  if (set == DataSet::VolumeMirrored) {
    for (ManifestClip& clip : manifest->clips) clip.mirror = true;
  }
  return manifest;
}

std::unique_ptr<Database> load_or_build(DataSet set) {
  const fs::path cache = work_dir() / (std::string(data_set_name(set)) + ".mmdb");
  if (fs::exists(cache)) {
    Result<Database> loaded = load_database(cache);
    // A cache from before the animation section (format 1) is rebuilt: the
    // controller benchmarks need poses.
    if (loaded && loaded->animation() != nullptr) return std::make_unique<Database>(std::move(loaded.value()));
    std::fprintf(stderr, "bench: ignoring cache: %s\n",
                 loaded ? "it has no animation section" : loaded.message().c_str());
  }
  Result<Manifest> manifest = manifest_for(set);
  if (!manifest) {
    std::fprintf(stderr, "bench: %s\n", manifest.message().c_str());
    return nullptr;
  }
  std::fprintf(stderr, "bench: building the %s database from %zu clips\n", data_set_name(set).data(),
               manifest->clips.size());
  ThreadPool pool;
  BuildOptions options;
  options.pool = &pool;
  Result<Database> built = build_database(*manifest, options);
  if (!built) {
    std::fprintf(stderr, "bench: %s\n", built.message().c_str());
    return nullptr;
  }
  fs::create_directories(work_dir());
  if (Status saved = save_database(*built, cache); !saved) {
    std::fprintf(stderr, "bench: cannot cache the database: %s\n", saved.message().c_str());
  }
  return std::make_unique<Database>(std::move(built.value()));
}

}  // namespace

std::string_view data_set_name(DataSet set) {
  switch (set) {
    case DataSet::Locomotion: return "locomotion";
    case DataSet::Volume: return "volume";
    case DataSet::VolumeMirrored: return "volume-mirrored";
  }
  return "unknown";
}

const Database* database(DataSet set) {
  // Benchmarks run on one thread; the cache lives as long as the process.
  static std::map<DataSet, std::unique_ptr<Database>> cache;
  auto found = cache.find(set);
  if (found == cache.end()) found = cache.emplace(set, load_or_build(set)).first;
  return found->second.get();
}

}  // namespace mmvk::bench
