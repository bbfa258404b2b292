#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, -DMMVK_FUZZ=ON) in build-fuzz/, writes
# the seed corpora and runs every target for SECONDS each (default 60).
# A finding stops with its crash file in build-fuzz/findings/<target>/;
# copy it into tests/corpus/<target>/ as a regression input once fixed.
#   tests/fuzz/run.sh [SECONDS] [JOBS]
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-60}
jobs=${2:-$(nproc)}
build=build-fuzz

cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ -DMMVK_FUZZ=ON \
  -DMMVK_BUILD_VULKAN=OFF -DMMVK_BUILD_HOST=OFF -DMMVK_BUILD_TESTS=OFF -DMMVK_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs"

seeds="$build/seeds"
rm -rf "$seeds"
"$build/tests/fuzz/fuzz_make_seeds" "$seeds" tests/corpus/bvh

# Scene seeds: fuzz_scene_import reads its bytes as decisions (node tree,
# bones, keys, metadata); a few fixed patterns start it off.
mkdir -p "$seeds/scene"
for pattern in 0123456789abcdef 1f1f1f1f1f1f1f1f 0307010302050102030405; do
  printf "%s%s%s%s" "$pattern" "$pattern" "$pattern" "$pattern" >"$seeds/scene/$pattern"
done

run() {  # target corpus-name [dict]
  local target=$1 corpus=$2 dict=${3:-}
  local work="$build/corpus/$target" findings="$build/findings/$target"
  mkdir -p "$work" "$findings"
  # Regression inputs first: every crash found so far must stay fixed.
  local regressions=()
  [ -d "tests/corpus/$target" ] && regressions=("tests/corpus/$target")
  echo "== $target: ${seconds}s"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
    LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0" \
    "$build/tests/fuzz/$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$findings/" -print_final_stats=1 ${dict:+-dict=$dict} \
    "$work" "$seeds/$corpus" "${regressions[@]}" 2>&1 | tail -n 15
}

run fuzz_bvh_build bvh tests/fuzz/bvh.dict
run fuzz_mmdb_load mmdb
run fuzz_mmdb_load_repair mmdb_repair
run fuzz_json json tests/fuzz/json.dict
run fuzz_cluster_table cluster_table
run fuzz_query_rows query
run fuzz_search_diff search_diff
run fuzz_scenario_json scenario tests/fuzz/json.dict
run fuzz_pose_targets pose_targets tests/fuzz/json.dict
run fuzz_scene_import scene
