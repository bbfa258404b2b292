#!/usr/bin/env bash
# The crowd's default data, candidate by candidate: every shipped set and the
# variants of CMU subject 16 that the database build and the crowd's controls
# allow (built from the shipped takes, with the shipped set's contact
# thresholds unless a row says otherwise), each run as a user runs the main job (1,000 characters x 20 s, the
# clusters backend, a fresh cache), printed as one Markdown table of the
# figures that decide the default (bench/RESULTS.md, "The default data").
#
# usage: bench/default_data_candidates.sh [path/to/mmvk]   (default build/host/mmvk)
# Quality figures do not depend on timing, so a busy machine changes none of them.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
mmvk=${1:-$root/build/host/mmvk}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmu16=$root/host/crowd/data/cmu16

# A manifest over the shipped subject 16 takes. $1: folder name, $2: takes
# (16_NN), $3: JSON fields added to the manifest (may be empty), $4: tags
# added to the jogs (may be empty).
manifest() {
  mkdir -p "$work/$1"
  python3 - "$work/$1/manifest.json" "$cmu16" "$2" "$3" "$4" <<'PY'
import json, sys
out, folder, takes, extra, jog_tags = sys.argv[1:]
known = {
    "16_23": ("walk_veer_left_23", ["walk"]),
    "16_27": ("walk_turn_left_27", ["walk", "turn"]),
    "16_41": ("jog_turn_left_41", ["jog", "turn"]),
    "16_43": ("jog_turn_right_43", ["jog", "turn"]),
    "16_50": ("run_veer_right_50", ["run"]),
    "16_57": ("jog_stop_57", ["jog", "stop"]),
}
clips = []
for take in takes.split():
    name, tags = known[take]
    if "jog" in tags and jog_tags:
        tags = tags + jog_tags.split()
    clips.append({"file": f"{folder}/{take}.bvh", "name": name, "tags": tags})
manifest = {"fps": 30, "mirror": True, "edge_rule": "extrapolate", "clips": clips}
if extra:
    manifest.update(json.loads(extra))
json.dump(manifest, open(out, "w"), indent=1)
PY
  echo "$work/$1/manifest.json"
}

all="16_23 16_27 16_41 16_43 16_50 16_57"
walks="16_23 16_27"
# The shipped cmu16 manifest's contact thresholds, and the defaults.
wide='{"contacts": {"enter_speed": 0.1, "exit_speed": 0.15}}'
all_default=$(manifest all16-default "$all" "" "")
jogs_run=$(manifest jogs-run "$all" "$wide" run)
walk16=$(manifest walk16 "$walks" "$wide" "")

# label | --data | extra crowd options. A shipped set runs with its own crowd
# settings (cmu-walk-run: correction half-life 0.07 s; cmu-walks 0.15 s) and
# a manifest with the crowd's (0.15 s) unless the row sets one.
candidates=(
  "cmu-walk-run, the default (CMU 16 walks, jogs, a run; gait tags)|cmu-walk-run|"
  "cmu-walk-run, correction 0.15 s|cmu-walk-run|--correction-half-life 0.15"
  "cmu-walk-run, correction 0.1 s|cmu-walk-run|--correction-half-life 0.1"
  "cmu-walk-run, default contact thresholds|$all_default|--correction-half-life 0.07"
  "cmu-walk-run, runners also search the jogs|$jogs_run|--correction-half-life 0.07"
  "CMU 16 walks only (16_23, 16_27)|$walk16|--correction-half-life 0.07"
  "cmu-walks (CMU 131, the default before)|cmu-walks|"
  "60 Hz: cmu-walk-run|cmu-walk-run|--rate 60"
  "60 Hz: cmu-walk-run, correction 0.15 s|cmu-walk-run|--correction-half-life 0.15 --rate 60"
  "60 Hz: CMU 16 walks only|$walk16|--correction-half-life 0.07 --rate 60"
  "60 Hz: cmu-walks|cmu-walks|--rate 60"
)
# The Bandai Namco locomotion set (non-commercial; not shipped), where the
# shared data is: foot IK changes are measured on it too.
bandai=$root/../shared/data/bandai-namco-nc/locomotion-normal
if [[ -d $bandai ]]; then
  candidates+=("Bandai locomotion (not shipped)|$bandai|" "60 Hz: Bandai locomotion|$bandai|--rate 60")
fi

echo "| candidate | frames | correction s | traj. error 1 s (m) | sliding cm/s (before IK) | transitions /s | walk / run m/s | runners | no_candidate | reach-clamped | knee p99 deg/s | pose accel. p99 elsewhere m/s^2 (clips) |"
echo "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|"
for entry in "${candidates[@]}"; do
  IFS='|' read -r label data extra <<<"$entry"
  cache=$(mktemp -d "$work/cache.XXXX")
  # shellcheck disable=SC2086  # $extra is a list of options
  XDG_CACHE_HOME=$cache "$mmvk" crowd --data "$data" --backend clusters --agents 1000 --seconds 20 \
    --summary "$cache/s.json" $extra >"$cache/log" 2>&1 || { echo "| $label | failed: $(tail -1 "$cache/log") |"; continue; }
  python3 - "$label" "$cache/s.json" <<'PY'
import json, sys
label, path = sys.argv[1:]
s = json.load(open(path))
run = "null" if s["run_mps"] is None else f"{s['run_mps']:.2f}"
print(f"| {label} | {s['database_frames']:,} | {s['correction_half_life_s']:g} | {s['trajectory_error_m_1s']:.4f} | "
      f"{s['foot_sliding_cm_s']:.2f} ({s['foot_sliding_before_ik_cm_s']:.1f}) | {s['transitions_per_agent_s']:.2f} | "
      f"{s['walk_mps']:.2f} / {run} | {s['runners']} | {s['no_candidate']} | "
      f"{100 * s['ik_reach_clamped_fraction']:.1f}% | {s['knee_speed_p99_deg_s']:.0f} | "
      f"{s['pose_acceleration_p99_m_s2']['elsewhere']:.1f} ({s['clips']['pose_acceleration_p99_m_s2']:.1f}) |")
PY
done
