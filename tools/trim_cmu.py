#!/usr/bin/env python3
"""Makes the crowd's shipped CMU locomotion sets from the BVH in ../shared/data.

Sets:
  cmu131  CMU subject 131's walks (amc2bvh conversions, 120 fps;
          ../shared/data/cmu/amc2bvh-131): start/walk/stop and curved walks.
  cmu16   CMU subject 16's walks, jogs and runs (cgspeed conversions, 120 fps;
          ../shared/data/cmu/cgspeed-16). Their frame 0 is a T-pose the
          converter added, dropped here; isolated one-frame spikes of a
          rotation channel (in the upstream data) are repaired first.

Each take keeps every 4th frame (120 -> 30 fps exactly, no interpolation
needed) and its channel values are rounded (positions to 1e-3 file units,
0.06 mm for CMU ASF units; angles to 1e-2 degrees), which keeps a set under
3 MB while changing joint positions by well under a millimetre.

usage: tools/trim_cmu.py SET SOURCE_DIR OUT_DIR
  e.g. tools/trim_cmu.py cmu16 ../shared/data/cmu/cgspeed-16 host/crowd/data/cmu16
"""
import os
import sys

STEP = 4  # 120 fps / 30 fps

# Per set: the takes, the source frames dropped at the start, and whether
# rotation spikes are repaired.
SETS = {
    # The walks: start/walk/stop, curved walks left, curved walks right. The
    # hops, ducks and jump-stops of the subject are left out: a crowd walks.
    "cmu131": {
        "takes": ["131_01", "131_02", "131_09", "131_10", "131_11", "131_12", "131_13", "131_14"],
        "skip": 0,
        "repair_spikes": False,
    },
    # Every subject 16 take in the shared data: walks (veer, 90-degree turn),
    # jogs (90-degree turns), runs (veer, sudden stop).
    "cmu16": {
        "takes": ["16_23", "16_27", "16_41", "16_43", "16_50", "16_57"],
        "skip": 1,
        "repair_spikes": True,
    },
}

# A rotation value this far (degrees) from the mean of its two neighbours,
# which agree with each other to within a third of that, is a one-frame
# spike: motion capture at 120 fps does not turn a toe by 8 degrees and back
# in 17 ms.
SPIKE_DEGREES = 3.0


def fmt(value, decimals):
    text = f"{value:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def repair_spikes(frames, kinds):
    """Replaces one-frame spikes of rotation channels by their neighbours' mean."""
    repaired = 0
    for f in range(1, len(frames) - 1):
        before, here, after = frames[f - 1], frames[f], frames[f + 1]
        for c, kind in enumerate(kinds):
            if kind != "r":
                continue
            mean = 0.5 * (before[c] + after[c])
            if abs(here[c] - mean) > SPIKE_DEGREES and abs(after[c] - before[c]) < SPIKE_DEGREES / 3:
                here[c] = mean
                repaired += 1
    return repaired


def trim(src, dst, skip, spikes):
    with open(src) as f:
        lines = f.read().split("\n")
    motion = lines.index("MOTION")
    header = lines[:motion]
    # Which channels are positions: walk the hierarchy's CHANNELS lines in order.
    kinds = []
    for line in header:
        parts = line.split()
        if parts and parts[0] == "CHANNELS":
            kinds += ["p" if name.endswith("position") else "r" for name in parts[2:]]
    frame_time = float(lines[motion + 2].split(":")[1])
    frames = [[float(v) for v in l.split()] for l in lines[motion + 3:] if l.strip()][skip:]
    for values in frames:
        assert len(values) == len(kinds), src
    repaired = repair_spikes(frames, kinds) if spikes else 0
    kept = frames[::STEP]
    out = header + ["MOTION", f"Frames: {len(kept)}", f"Frame Time: {frame_time * STEP:.8f}"]
    for values in kept:
        out.append(" ".join(fmt(v, 3 if k == "p" else 2) for v, k in zip(values, kinds)))
    with open(dst, "w") as f:
        f.write("\n".join(out) + "\n")
    return len(frames) + skip, len(kept), repaired


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in SETS:
        sys.exit(__doc__)
    chosen, src_dir, out_dir = SETS[sys.argv[1]], sys.argv[2], sys.argv[3]
    os.makedirs(out_dir, exist_ok=True)
    for take in chosen["takes"]:
        before, after, repaired = trim(os.path.join(src_dir, take + ".bvh"), os.path.join(out_dir, take + ".bvh"),
                                       chosen["skip"], chosen["repair_spikes"])
        print(f"{take}: {before} -> {after} frames" + (f", {repaired} spike values repaired" if repaired else ""))


if __name__ == "__main__":
    main()
