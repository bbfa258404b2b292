#!/usr/bin/env python3
"""Makes the crowd's default locomotion set from CMU subject 131.

Reads the amc2bvh conversions of CMU subject 131 (120 fps, see
../shared/data/SOURCES.md for how they were made), keeps the walking takes,
keeps every 4th frame (120 -> 30 fps exactly, no interpolation needed) and
rounds the channel values (positions to 1e-3 ASF units = 0.06 mm, angles to
1e-2 degrees), which brings the set under 3 MB while changing joint positions
by well under a millimetre.

usage: tools/trim_cmu131.py SOURCE_DIR OUT_DIR
"""
import os
import sys

# The walks: start/walk/stop, curved walks left, curved walks right. The
# hops, ducks and jump-stops of the subject are left out: a crowd walks.
TAKES = ["131_01", "131_02", "131_09", "131_10", "131_11", "131_12", "131_13", "131_14"]
STEP = 4  # 120 fps / 30 fps


def fmt(value, decimals):
    text = f"{value:.{decimals}f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def trim(src, dst):
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
    frames = [l for l in lines[motion + 3:] if l.strip()]
    kept = frames[::STEP]
    out = header + ["MOTION", f"Frames: {len(kept)}", f"Frame Time: {frame_time * STEP:.8f}"]
    for line in kept:
        values = [float(v) for v in line.split()]
        assert len(values) == len(kinds), src
        out.append(" ".join(fmt(v, 3 if k == "p" else 2) for v, k in zip(values, kinds)))
    with open(dst, "w") as f:
        f.write("\n".join(out) + "\n")
    return len(frames), len(kept)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src_dir, out_dir = sys.argv[1], sys.argv[2]
    os.makedirs(out_dir, exist_ok=True)
    for take in TAKES:
        before, after = trim(os.path.join(src_dir, take + ".bvh"), os.path.join(out_dir, take + ".bvh"))
        print(f"{take}: {before} -> {after} frames")


if __name__ == "__main__":
    main()
