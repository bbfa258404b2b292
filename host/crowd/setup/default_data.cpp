#include "setup/default_data.hpp"

#include <algorithm>
#include <cstdio>
#include <string_view>
#include <system_error>
#include <vector>

#include "setup/cache_entry.hpp"
#include "mmvk/common/hash.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/feature_schema.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/database/manifest.hpp"

namespace mmvk::crowd {

namespace {

// Bumped when the way the host builds databases changes (not the data).
constexpr std::uint32_t kRecipeVersion = 2;  // 2: mirrored spines keep their parent's reflection axis

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
  // The schema as parsed, inline or from its own file, and every file the
  // build reads (clips and sidecars): editing a schema file the manifest
  // names used to reuse the entry built with the old one.
  hash.add_text(schema_to_json(manifest.schema));
  for (const std::filesystem::path& file : manifest_input_files(manifest)) {
    MMVK_ASSIGN_OR_RETURN(const std::string bytes, read_file(file));
    hash.add_text(file.filename().string());
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
  // Each set's tuned crowd settings are in its manifest's "crowd" block
  // (bench/RESULTS.md, "The default data", has how they were chosen).
  // The first is the default: cmu-walk-run, the one set at a pedestrian pace
  // with a run, meets cmu-walks' figures (trajectory error, sliding) at 30
  // and 60 Hz (bench/RESULTS.md, "The default data").
  static constexpr ShippedData kShipped[] = {
      {"cmu-walk-run", "cmu16", "CMU 16 walks and runs",
       "CMU subject 16: walks (veer left, 90-degree left turn) at 1.6 m/s, jogs (90-degree turns, a jog "
       "to a stop) at 1.7-2.4 m/s, a run (veer right) at 3.6 m/s; tagged walk/jog/run; a 0.2 s standing loop "
       "cut from the stop's end, tagged stand. 6 short takes, 335 frames (11 s) at 30 fps, mirrored, "
       "trajectories extrapolated past the takes' ends",
       "stands: yes, starts: no, stops: yes, speeds: walk, jog, run"},
      {"cmu-walks", "cmu131", "CMU 131 walks",
       "CMU subject 131: start/walk/stop and curved walks at 0.2-0.7 m/s (stylised, slow); no run. "
       "8 takes and two 0.2 s standing loops cut from their ends (tagged stand), 2,889 frames at 30 fps, mirrored",
       "stands: yes, starts: yes, stops: yes, speeds: walk"},
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
  if (!shipped) return DataChoice{*data, data->string(), data->filename().string()};
  for (const auto& candidate : shipped_manifest_candidates(*shipped, executable)) {
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) {
      return DataChoice{candidate, "the " + std::string(shipped->label) + " (" + std::string(shipped->name) + ")",
                        std::string(shipped->label)};
    }
  }
  return make_error("the shipped motion set '" + std::string(shipped->name) + "' (host/crowd/data/" +
                    std::string(shipped->folder) +
                    ") was not found beside the program or in its source tree; pass --data DIR|manifest.json|db.mmdb");
}

namespace {

// Edits (insert, delete, replace one character) between two names.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// A missing --data that looks like a name (no folder, no extension) gets the
// nearest shipped set's name and the list: "cmu-walk" was meant as
// "cmu-walks" far more often than as a path.
std::string missing_data_message(const std::filesystem::path& source) {
  std::string message = source.string() + ": no such file or folder";
  if (source.has_parent_path() || source.has_extension()) return message;
  const ShippedData* nearest = nullptr;
  std::size_t best = 0;
  std::string names;
  for (const ShippedData& set : shipped_data()) {
    names += (names.empty() ? "" : ", ") + std::string(set.name);
    const std::size_t distance = edit_distance(source.string(), set.name);
    if (nearest == nullptr || distance < best) nearest = &set, best = distance;
  }
  message += ", nor a shipped motion set";
  if (nearest != nullptr && best <= std::max<std::size_t>(2, nearest->name.size() / 3)) {
    message += ": did you mean '" + std::string(nearest->name) + "'?";
  }
  return message + " (shipped: " + names + ")";
}

}  // namespace

Result<OpenedDatabase> open_database(const std::filesystem::path& source, const std::filesystem::path& cache_dir,
                                     const std::function<void(const std::string&)>& say) {
  std::error_code ec;
  if (!std::filesystem::exists(source, ec)) return make_error(missing_data_message(source));
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
