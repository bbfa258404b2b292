// libFuzzer target: bytes through assimp and mmvk's scene import (skeleton,
// sampling, units and axes) and the build's plausibility measures. The
// first byte picks the format as a file name's extension would (.fbx,
// .gltf, .glb, .dae); the rest is the file. Any input must end in a Result,
// never a crash, a sanitizer report or a hang. assimp itself is Debian's
// library, not instrumented: the coverage that guides the fuzzer is mmvk's
// side (what it does with whatever scene assimp returns), and assimp's own
// parsers are fuzzed upstream (OSS-Fuzz); a crash inside assimp still ends
// the run and is reported here.
#include <cstddef>
#include <cstdint>
#include <span>

#include "mmvk/import_check.hpp"
#include "mmvk/scene_import.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2 || size > 256 * 1024) return 0;
  static constexpr const char* kExtensions[] = {".fbx", ".gltf", ".glb", ".dae"};
  mmvk::SceneImportOptions options;
  options.fps = 30.0f;
  options.max_samples = 1 << 16;  // a claimed hour-long animation is an error, not a slow run
  mmvk::Result<mmvk::SceneImport> scene = mmvk::import_scene_from_memory(
      std::span(data + 1, size - 1), kExtensions[data[0] % 4], "fuzz", options);
  if (!scene.ok()) return 0;
  for (const mmvk::SceneAnimation& animation : scene->animations) (void)mmvk::measure_import(animation.motion);
  return 0;
}
