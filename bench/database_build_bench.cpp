// Database build throughput on bandai-namco-nc/locomotion-normal (145 clips,
// 21,791 frames at 30 fps), as frames/s (a kIsRate counter):
//   DatabaseBuild/threads:N   the whole build: parse BVH, import, character
//                             root, features, normalization, Database::create
//   FeatureExtraction         extract_features alone on motions already in memory
//   CharacterRoot             compute_character_root alone
//   Normalization             compute_normalization + apply_normalization
//   SaveLoad                  serialize_database + deserialize_database
// Data: MMVK_DATA or ../shared/data.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/import/character.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/features/features.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/features/normalization.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk {
namespace {

std::filesystem::path locomotion_dir() {
  const char* from_env = std::getenv("MMVK_DATA");
  const std::filesystem::path data = from_env && *from_env ? from_env : MMVK_DEFAULT_DATA_DIR;
  return data / "bandai-namco-nc" / "locomotion-normal";
}

struct LoadedSet {
  std::vector<Motion> motions;
  std::vector<CharacterRoot> roots;
  std::uint64_t frames = 0;
  std::string error;
};

// The locomotion set imported once per process.
const LoadedSet& loaded_set() {
  static const LoadedSet set = [] {
    LoadedSet out;
    Result<Manifest> manifest = manifest_from_directory(locomotion_dir());
    if (!manifest) {
      out.error = manifest.message();
      return out;
    }
    for (const ManifestClip& clip : manifest->clips) {
      Result<BvhFile> bvh = load_bvh(clip.file);
      Result<Motion> motion = bvh ? motion_from_bvh(*bvh, {}) : Result<Motion>(bvh.error());
      Result<CharacterRoot> root = motion ? compute_character_root(*motion, {}) : Result<CharacterRoot>(motion.error());
      if (!root) {
        out.error = root.message();
        return out;
      }
      out.frames += motion->frame_count;
      out.motions.push_back(std::move(*motion));
      out.roots.push_back(std::move(*root));
    }
    return out;
  }();
  return set;
}

void set_rate(benchmark::State& state, std::uint64_t frames_per_iteration) {
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames_per_iteration) * state.iterations(),
                                                  benchmark::Counter::kIsRate);
  state.counters["frames"] = static_cast<double>(frames_per_iteration);
}

void BM_DatabaseBuild(benchmark::State& state) {
  Result<Manifest> manifest = manifest_from_directory(locomotion_dir());
  if (!manifest) {
    state.SkipWithError(manifest.message().c_str());
    return;
  }
  ThreadPool pool(static_cast<unsigned>(state.range(0)));
  BuildOptions options;
  options.pool = &pool;
  std::uint64_t frames = 0;
  for (auto _ : state) {
    Result<Database> db = build_database(*manifest, options);
    if (!db) {
      state.SkipWithError(db.message().c_str());
      return;
    }
    frames = db->frame_count();
    benchmark::DoNotOptimize(db->features().data());
  }
  set_rate(state, frames);
}
BENCHMARK(BM_DatabaseBuild)->ArgName("threads")->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_FeatureExtraction(benchmark::State& state) {
  const LoadedSet& set = loaded_set();
  if (!set.error.empty()) {
    state.SkipWithError(set.error.c_str());
    return;
  }
  const FeatureSchema schema = default_schema();
  for (auto _ : state) {
    for (std::size_t i = 0; i < set.motions.size(); ++i) {
      Result<RawFeatures> raw = extract_features(set.motions[i], set.roots[i], schema, {});
      benchmark::DoNotOptimize(raw->values.data());
    }
  }
  set_rate(state, set.frames);
}
BENCHMARK(BM_FeatureExtraction)->Unit(benchmark::kMillisecond);

void BM_CharacterRoot(benchmark::State& state) {
  const LoadedSet& set = loaded_set();
  if (!set.error.empty()) {
    state.SkipWithError(set.error.c_str());
    return;
  }
  for (auto _ : state) {
    for (const Motion& motion : set.motions) {
      Result<CharacterRoot> root = compute_character_root(motion, {});
      benchmark::DoNotOptimize(root->positions.data());
    }
  }
  set_rate(state, set.frames);
}
BENCHMARK(BM_CharacterRoot)->Unit(benchmark::kMillisecond);

void BM_Normalization(benchmark::State& state) {
  const LoadedSet& set = loaded_set();
  if (!set.error.empty()) {
    state.SkipWithError(set.error.c_str());
    return;
  }
  const FeatureSchema schema = default_schema();
  std::vector<float> raw;
  for (std::size_t i = 0; i < set.motions.size(); ++i) {
    Result<RawFeatures> one = extract_features(set.motions[i], set.roots[i], schema, {});
    raw.insert(raw.end(), one->values.begin(), one->values.end());
  }
  std::vector<float> work(raw.size());
  for (auto _ : state) {
    work = raw;
    Result<std::vector<DimNormalization>> n = compute_normalization(schema, work);
    apply_normalization(*n, work);
    benchmark::DoNotOptimize(work.data());
  }
  set_rate(state, set.frames);
}
BENCHMARK(BM_Normalization)->Unit(benchmark::kMillisecond);

void BM_SaveLoad(benchmark::State& state) {
  const LoadedSet& set = loaded_set();
  if (!set.error.empty()) {
    state.SkipWithError(set.error.c_str());
    return;
  }
  std::vector<MotionClip> clips(set.motions.size());
  for (std::size_t i = 0; i < clips.size(); ++i) {
    clips[i].motion = set.motions[i];
    clips[i].meta.name = "clip" + std::to_string(i);
  }
  Result<Database> db = build_database_from_motions(clips, {});
  if (!db) {
    state.SkipWithError(db.message().c_str());
    return;
  }
  for (auto _ : state) {
    Result<Database> back = deserialize_database(serialize_database(*db), "bench.mmdb");
    benchmark::DoNotOptimize(back->features().data());
  }
  set_rate(state, db->frame_count());
}
BENCHMARK(BM_SaveLoad)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace mmvk
