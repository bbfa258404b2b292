// The databases benchmarks run on, built once per process from the real
// motion capture and cached as .mmdb files in the build tree:
//   Locomotion  - bandai-namco-nc/locomotion-normal (145 clips, ~22k frames)
//   Volume      - locomotion-normal + every volume/*.tar.xz archive, unpacked
//                 into the build tree (~417k frames)
//   VolumeMirrored - the same with a mirrored copy of every clip (~834k)
// The data folder is MMVK_DATA, or ../shared/data beside the checkout.
#pragma once

#include <string_view>

#include "mmvk/database.hpp"

namespace mmvk::bench {

enum class DataSet { Locomotion, Volume, VolumeMirrored };

std::string_view data_set_name(DataSet set);

// The database for `set`, built (or loaded from the cache) on first use.
// Returns nullptr after printing why when the data is missing or the build
// fails; the benchmark then reports an error instead of a number.
const Database* database(DataSet set);

}  // namespace mmvk::bench
