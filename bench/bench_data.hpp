// The databases benchmarks run on, built once per process from the real
// motion capture and cached as .mmdb files in the build tree:
//   Locomotion  - bandai-namco-nc/locomotion-normal (145 clips, ~22k frames)
//   Volume      - locomotion-normal + every volume/*.tar.xz archive, unpacked
//                 into the build tree (~417k frames)
//   VolumeMirrored - the same with a mirrored copy of every clip (~834k)
//   Volume104k - a real subset of Volume: every fourth clip of its manifest
//                in its fixed order (locomotion-normal first, then the two
//                Bandai volume datasets by file name), ~104k frames
// The data folder is MMVK_DATA, or ../shared/data beside the checkout.
//
// The suite (bench/suite) searches databases of its own kind: built with the
// "clamp" edge rule (every frame a candidate, so plain nearest-neighbour
// peers and mmvk answer the same question), without the animation section,
// and with the default 27-d schema or the wide schema of
// bench/schemas/wide60.json.
#pragma once

#include <string_view>

#include "mmvk/database/database.hpp"

namespace mmvk::bench {

enum class DataSet { Locomotion, Volume, VolumeMirrored, Volume104k };

std::string_view data_set_name(DataSet set);

// Where unpacked archives and cached databases and tables live:
// MMVK_BENCH_WORK_DIR from the environment when set (a build carried to
// another machine, bench/gpu_check.sh), else build/bench-data.
std::filesystem::path bench_work_dir();

// The database for `set`, built (or loaded from the cache) on first use.
// Returns nullptr after printing why when the data is missing or the build
// fails; the benchmark then reports an error instead of a number.
const Database* database(DataSet set);

// The suite's schemas: "default27" (default_schema()) and "wide60".
enum class SuiteSchema { Default27, Wide60 };
std::string_view suite_schema_name(SuiteSchema schema);

// The suite's database for (set, schema): every frame a candidate (edge rule
// clamp, no do-not-use ranges, multipliers 1, biases 0), no animation
// section; cached as <set>-<schema>-all.mmdb beside the others. nullptr
// after printing why, as database().
const Database* suite_database(DataSet set, SuiteSchema schema);

// CPU time of all the process's threads, in seconds (CLOCK_PROCESS_CPUTIME_ID).
double process_cpu_seconds();

}  // namespace mmvk::bench
