#!/usr/bin/env bash
# Crowd soak: runs `mmvk crowd` with 1,000 characters for TICKS
# ticks at 30 Hz on BACKEND, samples the process's resident memory (VmRSS)
# every SAMPLE seconds, and fails when
#   - the run fails,
#   - the RSS grows by more than LIMIT_MB MiB from the sample at 10% of the
#     run (after the database, the backend and the first batch exist) to the
#     end, or
#   - (Vulkan backends) the Khronos validation layer, enabled for the whole
#     run, prints any message.
# Not part of ctest: a soak runs for many minutes. Figures: bench/RESULTS.md.
#   bench/tools/crowd_soak.sh MMVK BACKEND TICKS OUTDIR [LIMIT_MB] [SAMPLE]
#   bench/tools/crowd_soak.sh build/host/mmvk fast-box 100000 /tmp/soak-cpu
#   bench/tools/crowd_soak.sh build/host/mmvk vulkan-brute 10000 /tmp/soak-vk
set -euo pipefail
mmvk=$1 backend=$2 ticks=$3 out=$4 limit_mb=${5:-16} sample=${6:-2}
mkdir -p "$out"
seconds=$(awk -v t="$ticks" 'BEGIN { printf "%.6f", t / 30 }')

env_args=()
case "$backend" in
  vulkan*) env_args=(VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation) ;;
esac

start=$(date +%s.%N)
env "${env_args[@]}" "$mmvk" crowd --agents 1000 --seconds "$seconds" --rate 30 --backend "$backend" \
  --summary "$out/summary.json" >"$out/stdout.txt" 2>"$out/stderr.txt" &
pid=$!
echo "seconds,rss_kib" >"$out/rss.csv"
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS:/ { print $2 }' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && echo "$(awk -v s="$start" -v n="$(date +%s.%N)" 'BEGIN { printf "%.1f", n - s }'),$rss" >>"$out/rss.csv"
  sleep "$sample"
done
status=0
wait "$pid" || status=$?
if [ "$status" -ne 0 ]; then
  echo "crowd_soak: mmvk crowd failed (exit $status):" >&2
  tail -n 5 "$out/stderr.txt" >&2
  exit 1
fi

# Start (first sample), baseline (10% of the run), middle, end, peak.
awk -F, -v limit="$limit_mb" '
  NR > 1 { t[++n] = $1; r[n] = $2; if ($2 > peak) peak = $2 }
  END {
    if (n < 3) { print "crowd_soak: too few RSS samples (" n ")"; exit 1 }
    b = int(n / 10) + 1; m = int(n / 2) + 1
    growth = (r[n] - r[b]) / 1024
    printf "rss_mib start %.1f (t=%ss) baseline %.1f (t=%ss) middle %.1f (t=%ss) end %.1f (t=%ss) peak %.1f\n",
      r[1] / 1024, t[1], r[b] / 1024, t[b], r[m] / 1024, t[m], r[n] / 1024, t[n], peak / 1024
    printf "growth baseline->end %.2f MiB (limit %s MiB), %d samples\n", growth, limit, n
    if (growth > limit) { print "crowd_soak: FAIL: memory grew past the limit"; exit 1 }
  }' "$out/rss.csv" | tee "$out/rss_summary.txt"
[ "${PIPESTATUS[0]}" -eq 0 ] || exit 1

messages=$(cat "$out/stdout.txt" "$out/stderr.txt" | { grep -c -i -E "validation (error|warning)|VUID-" || true; })
echo "validation messages: $messages" | tee -a "$out/rss_summary.txt"
[ "$messages" -eq 0 ] || { echo "crowd_soak: FAIL: validation messages in $out/stdout.txt / stderr.txt" >&2; exit 1; }
grep -o '"ticks": *[0-9]*\|"wall_seconds": *[0-9.e+-]*\|"tick_ms_p50": *[0-9.e+-]*\|"tick_ms_p99": *[0-9.e+-]*\|"queries_per_tick": *[0-9.e+-]*' "$out/summary.json" | tr '\n' ' ' | tee -a "$out/rss_summary.txt"
echo | tee -a "$out/rss_summary.txt"
echo "crowd_soak: OK" | tee -a "$out/rss_summary.txt"
