#!/usr/bin/env bash
# The GPU check: on a machine with a GPU, in at most 8 minutes,
#   1. lists the Vulkan devices (one line and exit 3 when there is no GPU
#      device: no loader, no driver, or only CPU devices such as lavapipe),
#   2. runs the Vulkan tests (every tests/vulkan executable) on the GPU,
#   3. runs the suite's rows (bench/suite) for vulkan-brute, vulkan-clusters,
#      vulkan-nprobe16/64 and, as the yardstick, the CPU fast-brute and
#      clusters, at B = 1 and 1024 on the Bandai volume set (416,845 frames)
#      and its mirrored copy (833,690),
#   4. runs the crowd (`mmvk crowd`) with 10,000 and 100,000 characters on
#      vulkan-clusters on the volume set,
# and prints one table (also written to OUT/table.md, beside the logs and
# the JSON of every step).
#
# The GPU machine has no network and none of this project's dependencies
# (Vulkan headers and glslang, Google Benchmark, GoogleTest), so the check
# runs a build carried from a Debian machine, made here by --prepare:
#
#   bench/gpu_check.sh --prepare        # here: builds build-gpu/, fills build-gpu/stage/
#
# The stage holds programs/programs.tar.xz (the programs and the shared
# libraries they need beyond glibc and libstdc++: Google Benchmark, assimp, the
# Vulkan loader) and the data in two parts, data-1/ and data-2/ (the volume
# archives and locomotion-normal are about 85 MB, more than one transfer of
# 64 MiB to the GPU machine may carry). The printed plan carries the
# programs and data-1/ with a first command, then the programs and data-2/
# with the second while the machine is warm (what a first command leaves in
# the working tree stays there).
#
#   bench/gpu_check.sh [--stage DIR] [--data DIR] [--work DIR] [--out DIR]
#                      [--tests-only] [--skip-tests] [--quick]
#
#   --stage DIR   the prepared stage (default build-gpu/stage); without its
#                 programs, those of --build DIR (default build/) are used
#   --data DIR    a data folder laid out as ../shared/data (bandai-namco-nc/
#                 locomotion-normal and volume/*.tar.xz); default: the stage's
#                 data parts, else MMVK_DATA, else ../shared/data
#   --work DIR    scratch: unpacked archives, databases, cluster tables
#                 (default /tmp/mmvk-gpu-check); never the data folder
#   --out DIR     logs, JSON and the table (default OUT, else WORK/out)
#   --tests-only  devices and the Vulkan tests only
#   --skip-tests  everything but the Vulkan tests
#   --quick       small sizes on any Vulkan device, lavapipe included (a test
#                 of this script where there is no GPU): locomotion (21,791
#                 frames), 1,000 and 2,000 characters, the Vulkan tests that
#                 take under a few seconds on lavapipe
#   --allow-cpu   run the full rows on a CPU Vulkan device (lavapipe) too
#   --crowds "A:S ..."  the crowd runs, characters:simulated seconds
#                 (default "10000:5 100000:2"; --quick "1000:1 2000:1")
#
# Exit status: 0 when every step ran and passed, 1 when a step failed, 2 on
# bad arguments or a missing program, 3 when there is no Vulkan GPU device.
set -uo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/.." && pwd)
stage=$root/build-gpu/stage
build=$root/build
data=""
work=/tmp/mmvk-gpu-check
out=${OUT:-}
mode=all
quick=0
prepare=0
allow_cpu=0
crowds=""

usage() { sed -n '2,/^set -uo/p' "${BASH_SOURCE[0]}" | sed '$d; s/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    --prepare) prepare=1 ;;
    --stage) stage=$(realpath -m "$2"); shift ;;
    --build) build=$(realpath -m "$2"); shift ;;
    --data) data=$(realpath -m "$2"); shift ;;
    --work) work=$(realpath -m "$2"); shift ;;
    --out) out=$(realpath -m "$2"); shift ;;
    --tests-only) mode=tests ;;
    --skip-tests) mode=rest ;;
    --quick) quick=1 ;;
    --allow-cpu) allow_cpu=1 ;;
    --crowds) crowds=$2; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "gpu_check: unknown argument '$1' (--help lists them)" >&2; exit 2 ;;
  esac
  shift
done

vulkan_tests=(vulkan_backend_registry_test vulkan_backend_suite_test vulkan_cluster_suite_test vulkan_faults_test
              vulkan_pipeline_cache_test vulkan_search_test vulkan_setup_test vulkan_time_ranges_test
              crowd_controller_vulkan_test)
programs=(mmvk mmvk_suite mmvk_vulkan_devices)

# ---------------------------------------------------------------- prepare
if [ "$prepare" = 1 ]; then
  set -e
  gpu_build=$root/build-gpu
  # FAISS and nanoflann are left out: the check runs no peer, and FAISS
  # would bring OpenBLAS (36 MB) along.
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  cmake -S "$root" -B "$gpu_build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" \
    -DCMAKE_DISABLE_FIND_PACKAGE_faiss=ON -DCMAKE_DISABLE_FIND_PACKAGE_nanoflann=ON >/dev/null
  targets=("${programs[@]}")
  for t in "${vulkan_tests[@]}"; do targets+=("mmvk_test_vulkan_$t"); done
  cmake --build "$gpu_build" -j "$(nproc)" --target "${targets[@]}"
  rm -rf "$stage"
  packing=$gpu_build/programs
  rm -rf "$packing"
  mkdir -p "$packing/bin" "$packing/lib" "$stage/programs" "$stage/data-1/bandai-namco-nc/volume" \
    "$stage/data-2/bandai-namco-nc/volume"
  cp "$gpu_build/host/mmvk" "$gpu_build/bench/mmvk_suite" "$gpu_build/bench/mmvk_vulkan_devices" "$packing/bin/"
  for t in "${vulkan_tests[@]}"; do cp "$gpu_build/tests/mmvk_test_vulkan_$t" "$packing/bin/"; done
  strip --strip-unneeded "$packing"/bin/* 2>/dev/null || true
  # Every shared library the programs load but glibc's, the compiler
  # runtime's and the GPU driver's own (those come with any Linux and with
  # the driver; a copy from here could clash with them there).
  ldd "$packing"/bin/* | awk '$2 == "=>" && $3 ~ /^\// { print $3 }' | sort -u | while read -r lib; do
    case "$(basename "$lib")" in
      libc.so*|libm.so*|libdl.so*|libpthread.so*|librt.so*|ld-linux*|libgcc_s.so*|libstdc++.so*) ;;
      *) cp -L "$lib" "$packing/lib/" ;;
    esac
  done
  # Compressed (21 MB of programs -> about 5): a transfer carries 64 MiB.
  tar -C "$packing" -cJf "$stage/programs/programs.tar.xz" bin lib
  # The data: locomotion-normal as one archive, then the volume archives,
  # largest first, into the part with room (each part under ~45 MB, so
  # that a part and the programs fit one transfer of 64 MiB).
  source_data=${MMVK_DATA:-$root/../shared/data}/bandai-namco-nc
  [ -d "$source_data/locomotion-normal" ] || { echo "gpu_check: no $source_data/locomotion-normal (set MMVK_DATA)" >&2; exit 2; }
  tar -C "$source_data" -cJf "$stage/data-1/bandai-namco-nc/locomotion-normal.tar.xz" locomotion-normal
  sizes=(0 0)
  sizes[0]=$(stat -c %s "$stage/data-1/bandai-namco-nc/locomotion-normal.tar.xz")
  : >"$stage/archives.txt"
  for archive in $(ls -S "$source_data"/volume/*.tar.xz); do
    size=$(stat -c %s "$archive")
    part=0
    [ $((sizes[0] + size)) -gt $((45 << 20)) ] && part=1
    sizes[part]=$((sizes[part] + size))
    cp "$archive" "$stage/data-$((part + 1))/bandai-namco-nc/volume/"
    basename "$archive" >>"$stage/archives.txt"
  done
  echo
  echo "gpu_check: stage ready in ${stage#$root/}:"
  du -sh "$stage/programs" "$stage/data-1" "$stage/data-2" | sed 's/^/  /'
  rel=${stage#$root/}
  cat <<EOF

On the GPU machine (the device tool's run), two calls back to back, the
second while the first one's machine is still warm:
  1. carry ["$rel/programs", "$rel/data-1"]
     command: bench/gpu_check.sh --tests-only          (devices and Vulkan tests, a few minutes at most)
  2. carry ["$rel/programs", "$rel/data-2"]
     command: bench/gpu_check.sh --skip-tests --out \$OUT  (suite rows and crowd, within 8 minutes)
Or in one call where the data is already there: bench/gpu_check.sh --data DIR --out \$OUT
EOF
  exit 0
fi

# ---------------------------------------------------------------- run
# Every log and JSON goes to WORK/logs; OUT gets the few files worth
# keeping (the device tool brings back at most 8): table.md, steps.log,
# suite.json, the crowd summaries and logs.tar.gz with the rest.
out=${out:-$work/out}
logs=$work/logs
rm -rf "$logs"
mkdir -p "$work" "$out" "$logs"
log() { echo "gpu_check: $*" | tee -a "$logs/steps.log"; }
finish() {
  cp "$logs"/table.md "$logs"/steps.log "$logs"/suite.json "$logs"/crowd-*.json "$out/" 2>/dev/null
  tar -C "$logs" -czf "$out/logs.tar.gz" . 2>/dev/null
  exit "$1"
}
failed=0
start_all=$(date +%s)

# Programs: the stage's, else the build tree's.
if [ -f "$stage/programs/programs.tar.xz" ]; then
  rm -rf "$work/programs"
  mkdir -p "$work/programs"
  tar -C "$work/programs" -xJf "$stage/programs/programs.tar.xz" || { echo "gpu_check: cannot unpack the programs" >&2; exit 2; }
  bin=$work/programs/bin
  export LD_LIBRARY_PATH=$work/programs/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
  path_of() { echo "$bin/$1"; }
else
  path_of() {
    case "$1" in
      mmvk) echo "$build/host/mmvk" ;;
      mmvk_suite|mmvk_vulkan_devices) echo "$build/bench/$1" ;;
      *) echo "$build/tests/$1" ;;
    esac
  }
fi
for p in "${programs[@]}"; do
  [ -x "$(path_of "$p")" ] || { echo "gpu_check: $(path_of "$p") is missing (run --prepare here, carry the stage)" >&2; exit 2; }
done
if missing=$(ldd "$(path_of mmvk_suite)" 2>&1 | grep "not found"); then
  echo "gpu_check: shared libraries not found: $(echo "$missing" | awk '{print $1}' | tr '\n' ' ')" >&2
  exit 2
fi

# 1. The Vulkan driver and devices. On the GPU machine the loader is pointed
# at the NVIDIA driver alone, so that every Vulkan step runs on the GPU.
if [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]; then
  if [ "$quick" = 1 ]; then
    icd=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
  else
    icd=""
    for d in /usr/local/nvidia/share/vulkan/icd.d /usr/share/vulkan/icd.d /etc/vulkan/icd.d /usr/local/share/vulkan/icd.d; do
      [ -f "$d/nvidia_icd.json" ] && { icd=$d/nvidia_icd.json; break; }
    done
  fi
  [ -n "$icd" ] && [ -f "$icd" ] && export VK_DRIVER_FILES=$icd
fi
devices=$("$(path_of mmvk_vulkan_devices)" 2>&1)
device_status=$?
echo "$devices" >"$logs/devices.txt"
if [ $device_status -ne 0 ]; then
  log "$devices${VK_DRIVER_FILES:+ (VK_DRIVER_FILES=$VK_DRIVER_FILES)}"
  finish 3
fi
if [ "$quick" = 0 ] && [ "$allow_cpu" = 0 ] && ! grep -q -E '\| (discrete|integrated|virtual)-gpu \|' <<<"$devices"; then
  log "no Vulkan GPU device, only: $(cut -d'|' -f1 <<<"$devices" | sed 's/^device [0-9]*: //; s/ *$//' | paste -sd ';')"
  finish 3
fi
log "Vulkan devices${VK_DRIVER_FILES:+ (VK_DRIVER_FILES=$VK_DRIVER_FILES)}:"
sed 's/^/  /' <<<"$devices" | tee -a "$logs/steps.log"

# 2. The Vulkan tests, each executable whole (quick: the short ones).
tests_summary=""
if [ "$mode" != rest ]; then
  tests=("${vulkan_tests[@]}")
  [ "$quick" = 1 ] && tests=(vulkan_backend_registry_test vulkan_setup_test vulkan_faults_test vulkan_time_ranges_test)
  passed=0 failed_tests=0 bad=()
  t0=$(date +%s)
  for t in "${tests[@]}"; do
    exe=$(path_of "mmvk_test_vulkan_$t")
    if [ ! -x "$exe" ]; then bad+=("$t(missing)"); continue; fi
    MMVK_REQUIRE_VULKAN=1 XDG_RUNTIME_DIR=/tmp timeout 240 "$exe" --gtest_brief=1 >"$logs/test-$t.log" 2>&1
    rc=$?
    p=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$logs/test-$t.log" | tail -1)
    f=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$logs/test-$t.log" | tail -1)
    passed=$((passed + ${p:-0})); failed_tests=$((failed_tests + ${f:-0}))
    [ $rc -ne 0 ] && bad+=("$t(exit $rc)")
  done
  tests_summary="${#tests[@]} executables, $passed tests passed, $failed_tests failed, $(( $(date +%s) - t0 )) s"
  [ ${#bad[@]} -gt 0 ] && { tests_summary+="; failing: ${bad[*]}"; failed=1; }
  log "Vulkan tests: $tests_summary"
  echo "$tests_summary" | tee "$logs/tests.txt" >"$work/tests.txt"
fi
if [ "$mode" = tests ]; then
  log "done in $(( $(date +%s) - start_all )) s (tests only)"
  finish $failed
fi

# 3. The data: a folder laid out as ../shared/data, assembled from the
# stage's parts when --data is not given.
expected=()
[ -f "$stage/archives.txt" ] && mapfile -t expected <"$stage/archives.txt"
if [ -z "$data" ] && [ -d "$stage/data-1" ]; then
  data=$work/data
  mkdir -p "$data/bandai-namco-nc/volume"
  if [ ! -d "$data/bandai-namco-nc/locomotion-normal" ]; then
    tar -C "$data/bandai-namco-nc" -xJf "$stage/data-1/bandai-namco-nc/locomotion-normal.tar.xz" || failed=1
  fi
  for part in "$stage"/data-*/bandai-namco-nc/volume; do
    for a in "$part"/*.tar.xz; do [ -f "$a" ] && ln -sf "$a" "$data/bandai-namco-nc/volume/"; done
  done
fi
[ -z "$data" ] && data=${MMVK_DATA:-$root/../shared/data}
data=$(realpath -m "$data")
export MMVK_DATA=$data MMVK_BENCH_WORK_DIR=$work/bench-data XDG_CACHE_HOME=$work/cache
mkdir -p "$MMVK_BENCH_WORK_DIR" "$XDG_CACHE_HOME"
have=$(ls "$data/bandai-namco-nc/volume/"*.tar.xz 2>/dev/null | wc -l)
absent=()
for a in "${expected[@]}"; do [ -e "$data/bandai-namco-nc/volume/$a" ] || absent+=("$a"); done
volume=1
if [ "$quick" = 1 ]; then
  volume=0
elif [ "$have" -eq 0 ] || [ ${#absent[@]} -gt 0 ]; then
  volume=0
  log "the volume set is incomplete in $data (${#absent[@]} of ${#expected[@]} archives absent: ${absent[*]:-all}); the rows run on locomotion instead"
fi

# Unpacked once into the work folder (in parallel), where bench/bench_data
# looks for it; then the crowd's manifest of the same clips in the same order.
if [ "$volume" = 1 ] && [ ! -f "$MMVK_BENCH_WORK_DIR/volume/.unpacked" ]; then
  t0=$(date +%s)
  mkdir -p "$MMVK_BENCH_WORK_DIR/volume"
  if printf '%s\0' "$data"/bandai-namco-nc/volume/*.tar.xz |
       xargs -0 -P "$(nproc)" -I{} tar -xJf {} -C "$MMVK_BENCH_WORK_DIR/volume"; then
    : >"$MMVK_BENCH_WORK_DIR/volume/.unpacked"
    log "unpacked $have archives in $(( $(date +%s) - t0 )) s"
  else
    log "unpacking the volume archives failed"; failed=1; volume=0
  fi
fi
crowd_data=$data/bandai-namco-nc/locomotion-normal
if [ "$volume" = 1 ]; then
  crowd_data=$work/volume-manifest.json
  python3 - "$data/bandai-namco-nc/locomotion-normal" "$MMVK_BENCH_WORK_DIR/volume" "$crowd_data" <<'EOF'
import json, pathlib, sys
folders = [pathlib.Path(sys.argv[1])] + [pathlib.Path(sys.argv[2]) / d / "data" for d in
           ("Bandai-Namco-Research-Motiondataset-1", "Bandai-Namco-Research-Motiondataset-2")]
clips = [{"file": str(f)} for folder in folders for f in sorted(folder.iterdir()) if f.suffix.lower() == ".bvh"]
pathlib.Path(sys.argv[3]).write_text(json.dumps({"clips": clips}))
EOF
fi

# 4. The suite's rows.
if [ "$volume" = 1 ]; then
  sets='(volume|volume-mirrored)'; methods='fast-brute|clusters|vulkan-brute|vulkan-clusters|vulkan-nprobe16|vulkan-nprobe64'
else
  sets='locomotion'; methods='fast-brute|clusters|vulkan-brute|vulkan-clusters'
fi
t0=$(date +%s)
timeout 300 "$(path_of mmvk_suite)" "--benchmark_filter=^suite/$sets/default27/transition/($methods)/B:(1|1024)/" \
  --benchmark_min_time=0.2 --benchmark_out="$logs/suite.json" --benchmark_out_format=json \
  >"$logs/suite.log" 2>&1 || { log "the suite failed (exit $?, $logs/suite.log)"; failed=1; }
log "suite rows in $(( $(date +%s) - t0 )) s"

# 5. The crowd on vulkan-clusters (the first run builds the database from
# the manifest and caches it with its cluster table under XDG_CACHE_HOME).
if [ -z "$crowds" ]; then
  crowds="10000:5 100000:2"
  [ "$quick" = 1 ] && crowds="1000:1 2000:1"
fi
for c in $crowds; do
  agents=${c%%:*} seconds=${c#*:}
  t0=$(date +%s)
  timeout 240 "$(path_of mmvk)" crowd --data "$crowd_data" --agents "$agents" --seconds "$seconds" \
    --backend vulkan-clusters --summary "$logs/crowd-$agents.json" >"$logs/crowd-$agents.log" 2>&1 ||
    { log "the crowd with $agents characters failed (exit $?, $logs/crowd-$agents.log)"; failed=1; }
  log "crowd, $agents characters, in $(( $(date +%s) - t0 )) s"
done

# 6. One table.
# A --skip-tests run reports the tests of an earlier --tests-only run on
# the same machine (the two-call plan of --prepare).
if [ -z "$tests_summary" ]; then
  tests_summary="not run (--skip-tests)"
  [ -f "$work/tests.txt" ] && tests_summary="$(cat "$work/tests.txt") (the earlier --tests-only run)"
fi
python3 - "$logs" "$tests_summary" "$(( $(date +%s) - start_all ))" <<'EOF' | tee "$logs/table.md"
import json, pathlib, sys
out, tests, seconds = pathlib.Path(sys.argv[1]), sys.argv[2], sys.argv[3]
devices = (out / "devices.txt").read_text().strip().splitlines()
print(f"| GPU check ({seconds} s) | |\n|---|---|")
for d in devices:
    print(f"| Vulkan {d.split(':', 1)[0]} | {d.split(':', 1)[1].strip().replace(' | ', '; ')} |")
print(f"| Vulkan tests | {tests} |\n")
suite = out / "suite.json"
cells = {}
if suite.exists():
    for b in json.loads(suite.read_text()).get("benchmarks", []):
        if b.get("run_type") != "iteration" or b.get("error_occurred"):
            continue
        parts = b["run_name"].split("/")
        cells[(parts[1], parts[4], parts[5])] = b
print("| set | N | method | B | µs/query | kernel µs/query | rows evaluated | recall@1 | speed vs vulkan-brute | vs CPU clusters | device MiB |")
print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for (dataset, method, batch), b in sorted(cells.items(), key=lambda kv: (kv[1]["N"], kv[0][2], kv[0][1])):
    def speed_vs(other):
        base = cells.get((dataset, other, batch))
        return f"{base['us_per_query'] / b['us_per_query']:.2f}x" if base else "–"
    kernel = f"{b['kernel_us_per_query']:.1f}" if b.get("kernel_us_per_query", 0) > 0 else "–"
    device = f"{b['device_bytes'] / 2**20:.0f}" if b.get("device_bytes", 0) > 0 else "–"
    print(f"| {dataset} | {b['N']:,.0f} | {method} | {batch[2:]} | {b['us_per_query']:.1f} | {kernel} | "
          f"{100 * b['rows_fraction']:.2f}% | {b['recall1']:.4f} | {speed_vs('vulkan-brute')} | {speed_vs('clusters')} | {device} |")
if not cells:
    print("| (no suite rows: see suite.log) ||||||||||| ")
print("\n| crowd | frames | backend | device | queries/tick | search ms p50 / p99 | tick ms p50 / p99 | x real time: p50 tick / whole run |")
print("|---|---:|---|---|---:|---:|---:|---:|")
for f in sorted(out.glob("crowd-*.json"), key=lambda p: int(p.stem.split("-")[1])):
    s = json.loads(f.read_text())
    print(f"| {s['agents']:,} characters, {s['seconds']:g} s | {s['database_frames']:,} | {s['backend']} | {s['device']} | "
          f"{s['queries_per_tick']:.0f} | {s['search_ms_p50']:.2f} / {s['search_ms_p99']:.2f} | "
          f"{s['tick_ms_p50']:.2f} / {s['tick_ms_p99']:.2f} | "
          f"{1000 / s['rate_hz'] / s['tick_ms_p50']:.2f} / {s['realtime_factor']:.2f} |")
EOF
log "done in $(( $(date +%s) - start_all )) s; table, JSON and logs in $out"
finish $failed
