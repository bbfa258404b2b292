// libFuzzer target: BVH text through the parser, the importer and a database
// build (features, normalization, plausibility checks). Any input must end
// in a Result, never a crash, a sanitizer report or a hang.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "mmvk/import/bvh.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/import/motion.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Larger inputs only make each run slower; the parser's limits are
  // covered by its unit tests.
  if (size > 64 * 1024) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  mmvk::Result<mmvk::BvhFile> file = mmvk::parse_bvh(text, "fuzz.bvh");
  if (!file.ok()) return 0;
  mmvk::Result<mmvk::Motion> motion = mmvk::motion_from_bvh(*file, mmvk::ImportOptions{});
  if (!motion.ok() || motion->frame_count > 4096) return 0;
  std::vector<mmvk::MotionClip> clips(1);
  clips[0].meta.file = "fuzz.bvh";
  clips[0].meta.name = "fuzz";
  clips[0].motion = std::move(*motion);
  mmvk::MotionBuildSettings settings;
  settings.edge_rule = mmvk::EdgeRule::Clamp;  // short clips still give frames
  (void)mmvk::build_database_from_motions(clips, settings);
  return 0;
}
