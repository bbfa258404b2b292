#include "bench_data.hpp"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <utility>
#include <vector>
#include <string>

#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::bench {

namespace fs = std::filesystem;

namespace {

fs::path data_dir() {
  const char* from_env = std::getenv("MMVK_DATA");
  return from_env && *from_env ? fs::path(from_env) : fs::path(MMVK_DEFAULT_DATA_DIR);
}


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
  const fs::path volume = bench_work_dir() / "volume";
  if (!unpack_volume(volume)) return make_error("bench: the volume archives could not be unpacked");
  for (const char* dataset : {"Bandai-Namco-Research-Motiondataset-1", "Bandai-Namco-Research-Motiondataset-2"}) {
    Result<Manifest> part = manifest_from_directory(volume / dataset / "data");
    if (!part) return part.error();
    manifest->clips.insert(manifest->clips.end(), part->clips.begin(), part->clips.end());
  }
  if (set == DataSet::VolumeMirrored) {
    for (ManifestClip& clip : manifest->clips) clip.mirror = true;
  }
  if (set == DataSet::Volume104k) {
    // Every fourth clip: a quarter of the frames, spread over every kind of
    // motion the set holds, the same subset on every machine.
    std::vector<ManifestClip> kept;
    for (std::size_t c = 0; c < manifest->clips.size(); c += 4) kept.push_back(manifest->clips[c]);
    manifest->clips = std::move(kept);
  }
  return manifest;
}

// What a database is built with, beside its data set.
struct Variant {
  std::string cache_name;
  std::optional<FeatureSchema> schema;  // none: the manifest's (the default)
  bool all_candidates = false;          // edge rule clamp
  bool animation = true;
};

std::unique_ptr<Database> load_or_build(DataSet set, const Variant& variant) {
  const fs::path cache = bench_work_dir() / (variant.cache_name + ".mmdb");
  if (fs::exists(cache)) {
    Result<Database> loaded = load_database(cache);
    // A cache from before the animation section (format 1) is rebuilt: the
    // controller benchmarks need poses.
    if (loaded && (loaded->animation() != nullptr || !variant.animation)) {
      return std::make_unique<Database>(std::move(loaded.value()));
    }
    std::fprintf(stderr, "bench: ignoring cache: %s\n",
                 loaded ? "it has no animation section" : loaded.message().c_str());
  }
  Result<Manifest> manifest = manifest_for(set);
  if (!manifest) {
    std::fprintf(stderr, "bench: %s\n", manifest.message().c_str());
    return nullptr;
  }
  if (variant.schema) manifest->schema = *variant.schema;
  if (variant.all_candidates) manifest->edge_rule = EdgeRule::Clamp;
  std::fprintf(stderr, "bench: building the %s database from %zu clips\n", variant.cache_name.c_str(),
               manifest->clips.size());
  ThreadPool pool;
  BuildOptions options;
  options.pool = &pool;
  options.animation.enabled = variant.animation;
  Result<Database> built = build_database(*manifest, options);
  if (!built) {
    std::fprintf(stderr, "bench: %s\n", built.message().c_str());
    return nullptr;
  }
  fs::create_directories(bench_work_dir());
  if (Status saved = save_database(*built, cache); !saved) {
    std::fprintf(stderr, "bench: cannot cache the database: %s\n", saved.message().c_str());
  }
  return std::make_unique<Database>(std::move(built.value()));
}

}  // namespace

fs::path bench_work_dir() {
  const char* from_env = std::getenv("MMVK_BENCH_WORK_DIR");
  return from_env && *from_env ? fs::path(from_env) : fs::path(MMVK_BENCH_WORK_DIR);
}

std::string_view data_set_name(DataSet set) {
  switch (set) {
    case DataSet::Locomotion: return "locomotion";
    case DataSet::Volume: return "volume";
    case DataSet::VolumeMirrored: return "volume-mirrored";
    case DataSet::Volume104k: return "volume104k";
  }
  return "unknown";
}

const Database* database(DataSet set) {
  // Benchmarks run on one thread; the cache lives as long as the process.
  static std::map<DataSet, std::unique_ptr<Database>> cache;
  auto found = cache.find(set);
  if (found == cache.end()) {
    Variant variant;
    variant.cache_name = data_set_name(set);
    found = cache.emplace(set, load_or_build(set, variant)).first;
  }
  return found->second.get();
}

std::string_view suite_schema_name(SuiteSchema schema) {
  switch (schema) {
    case SuiteSchema::Default27: return "default27";
    case SuiteSchema::Wide60: return "wide60";
  }
  return "unknown";
}

const Database* suite_database(DataSet set, SuiteSchema schema) {
  static std::map<std::pair<DataSet, SuiteSchema>, std::unique_ptr<Database>> cache;
  auto found = cache.find({set, schema});
  if (found != cache.end()) return found->second.get();
  Variant variant;
  variant.cache_name = std::string(data_set_name(set)) + "-" + std::string(suite_schema_name(schema)) + "-all";
  variant.all_candidates = true;
  variant.animation = false;
  std::unique_ptr<Database> built;
  if (schema == SuiteSchema::Wide60) {
    Result<FeatureSchema> wide = load_schema(fs::path(MMVK_BENCH_SOURCE_DIR) / "schemas" / "wide60.json");
    if (wide) {
      variant.schema = std::move(wide.value());
    } else {
      std::fprintf(stderr, "bench: %s\n", wide.message().c_str());
    }
  }
  if (schema == SuiteSchema::Default27 || variant.schema) built = load_or_build(set, variant);
  return cache.emplace(std::make_pair(set, schema), std::move(built)).first->second.get();
}

double process_cpu_seconds() {
  timespec now{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return double(now.tv_sec) + double(now.tv_nsec) * 1e-9;
}

}  // namespace mmvk::bench
