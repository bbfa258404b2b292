#include "default_data.hpp"

#include <cstdio>
#include <system_error>

#include "cache_entry.hpp"
#include "mmvk/hash.hpp"
#include "mmvk/database_build.hpp"
#include "mmvk/database_io.hpp"
#include "mmvk/file_io.hpp"
#include "mmvk/manifest.hpp"

namespace mmvk::crowd {

namespace {

// Bumped when the way the host builds databases changes (not the data).
constexpr std::uint32_t kRecipeVersion = 1;

// The digest of everything a build reads: the manifest (or folder listing)
// and the bytes of every clip.
Result<std::uint64_t> source_digest(const std::filesystem::path& source, const Manifest& manifest) {
  Hasher hash;
  hash.add_u32(kRecipeVersion);
  hash.add_u32(kDatabaseFormatVersion);
  // The one reader: regular files only, so a clip that is a FIFO fails
  // instead of blocking the digest.
  if (!std::filesystem::is_directory(source)) {
    MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(source, ReadOptions{kMaxJsonBytes, false}));
    hash.add_text(bytes);
  }
  for (const ManifestClip& clip : manifest.clips) {
    MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(clip.file));
    hash.add_text(clip.file.filename().string());
    hash.add_text(bytes);
  }
  return hash.digest();
}

std::string hex(std::uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(value));
  return text;
}

}  // namespace

std::span<const ShippedData> shipped_data() {
  // Correction half-lives: the largest that keeps each set's trajectory
  // error at 1 s within 0.0415 m at 30 and 60 Hz (1,000 characters x 20 s):
  // CMU 131 0.0405 / 0.0415 m at 0.15 s; CMU 16, whose takes are 1-2.5 s
  // long at 2.5 times the pace, 0.0685 / 0.0705 m at 0.15 s, 0.0495 at 0.1 s,
  // 0.0395 / 0.0405 m at 0.07 s.
  // The first is the default: cmu-walk-run, the one set at a pedestrian pace
  // with a run, meets cmu-walks' figures (trajectory error, sliding) at 30
  // and 60 Hz (bench/RESULTS.md, "The default data").
  static constexpr ShippedData kShipped[] = {
      {"cmu-walk-run", "cmu16", "CMU 16 walks and runs",
       "CMU subject 16: walks (veer left, 90-degree left turn) at 1.6 m/s, jogs (90-degree turns, a jog "
       "to a stop) at 1.7-2.4 m/s, a run (veer right) at 3.6 m/s; tagged walk/jog/run. 6 short takes, 329 "
       "frames (11 s) at 30 fps, mirrored, trajectories extrapolated past the takes' ends",
       0.07f},
      {"cmu-walks", "cmu131", "CMU 131 walks",
       "CMU subject 131: start/walk/stop and curved walks at 0.2-0.7 m/s (stylised, slow); no run. "
       "8 takes, 2,876 frames at 30 fps, mirrored",
       0.15f},
  };
  return kShipped;
}

const ShippedData* find_shipped_data(std::string_view name) {
  for (const ShippedData& data : shipped_data()) {
    if (data.name == name) return &data;
  }
  return nullptr;
}

std::vector<std::filesystem::path> shipped_manifest_candidates(const ShippedData& data,
                                                               const std::filesystem::path& executable) {
  std::vector<std::filesystem::path> candidates;
  if (!executable.empty()) {
    candidates.push_back(executable.parent_path() / ".." / "share" / "mmvk" / "crowd" / data.folder / "manifest.json");
  }
#if defined(MMVK_CROWD_SOURCE_DATA_DIR)
  candidates.push_back(std::filesystem::path(MMVK_CROWD_SOURCE_DATA_DIR) / data.folder / "manifest.json");
#endif
  return candidates;
}

Result<DataChoice> choose_data(const std::optional<std::filesystem::path>& data,
                               const std::filesystem::path& executable) {
  // An empty path read as ": no such file or folder", naming nothing.
  if (data && data->empty()) {
    return make_error("--data is empty: name a shipped motion set, a folder of BVH, a manifest or a .mmdb");
  }
  const ShippedData* shipped = data ? find_shipped_data(data->string()) : &shipped_data()[0];
  if (!shipped) return DataChoice{*data, data->string(), data->filename().string(), std::nullopt};
  for (const auto& candidate : shipped_manifest_candidates(*shipped, executable)) {
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) {
      return DataChoice{candidate, "the " + std::string(shipped->label) + " (" + std::string(shipped->name) + ")",
                        std::string(shipped->label), shipped->correction_half_life};
    }
  }
  return make_error("the shipped motion set '" + std::string(shipped->name) + "' (host/crowd/data/" +
                    std::string(shipped->folder) +
                    ") was not found beside the program or in its source tree; pass --data DIR|manifest.json|db.mmdb");
}

Result<OpenedDatabase> open_database(const std::filesystem::path& source, const std::filesystem::path& cache_dir,
                                     const std::function<void(const std::string&)>& say) {
  std::error_code ec;
  if (!std::filesystem::exists(source, ec)) return make_error(source.string() + ": no such file or folder");
  if (source.extension() == ".mmdb" || has_database_magic(source)) {
    MMVK_ASSIGN_OR_RETURN(Database database, load_database(source));
    return OpenedDatabase{std::move(database), source, false};
  }
  MMVK_ASSIGN_OR_RETURN(Manifest manifest, load_manifest_or_directory(source));
  MMVK_ASSIGN_OR_RETURN(const std::uint64_t digest, source_digest(source, manifest));
  const std::string stem = std::filesystem::is_directory(source) ? source.filename().string() : source.stem().string();
  const std::string label = (stem.empty() || stem == "manifest") ? source.parent_path().filename().string() : stem;
  std::filesystem::path cached;
  if (!cache_dir.empty()) {
    cached = cache_dir / ("crowd-" + label + "-" + hex(digest) + ".mmdb");
    if (std::filesystem::exists(cached, ec)) {
      Result<Database> loaded = load_database(cached);
      const Status valid = loaded ? validate_cache_entry(*loaded, manifest) : Status(loaded.error());
      if (valid) return OpenedDatabase{std::move(loaded.value()), cached, false};
      say("the cached database " + cached.string() + " is not usable (" + valid.message() + "); rebuilding it");
    }
  }
  say("building the database from " + source.string() + " (" + std::to_string(manifest.clips.size()) +
      " clips; once, then cached)");
  MMVK_ASSIGN_OR_RETURN(Database database, build_database(manifest));
  if (!cached.empty()) {
    std::filesystem::create_directories(cache_dir, ec);
    // A cache entry: whatever stands at its name is replaced, never written through.
    if (Status saved = write_file_atomically(cached, serialize_database(database), OutputPolicy::CacheEntry); !saved) {
      say("could not cache the database (" + saved.message() + "); it will be built again next time");
      cached.clear();
    } else {
      say("cached the database at " + cached.string());
    }
  }
  return OpenedDatabase{std::move(database), cached, true};
}

}  // namespace mmvk::crowd
