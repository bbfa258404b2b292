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

# Scene files: assimp-testmodels' animated skeletons, each behind the byte
# that picks its format (fuzz_scene_import.cpp: 0 .fbx, 1 .gltf, 3 .dae).
models=/usr/share/assimp/models
mkdir -p "$seeds/scene"
scene_seed() {  # selector-byte file
  [ -f "$2" ] && { printf "\\$(printf '%03o' "$1")"; cat "$2"; } >"$seeds/scene/$(basename "$2")"
  return 0
}
scene_seed 0 "$models/FBX/animation_with_skeleton.fbx"
scene_seed 0 "$models/FBX/huesitos.fbx"
scene_seed 1 "$models/glTF2/simple_skin/simple_skin.gltf"
scene_seed 3 "$models/Collada/box_nested_animation.dae"

run() {  # target corpus-name [dict]
  local target=$1 corpus=$2 dict=${3:-}
  local work="$build/corpus/$target" findings="$build/findings/$target"
  mkdir -p "$work" "$findings"
  # Regression inputs first: every crash found so far must stay fixed.
  local regressions=()
  [ -d "tests/corpus/$target" ] && regressions=("tests/corpus/$target")
  echo "== $target: ${seconds}s"
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
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
