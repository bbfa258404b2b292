#!/usr/bin/env python3
"""Write a learned-phase sidecar from a NumPy array and build a database with it.

    PYTHONPATH=build/python python3 host/examples/python/phase_sidecar.py --out /tmp/phase-example

A phase model (a Periodic Autoencoder, DeepPhase) trained elsewhere gives
each frame a phase and an amplitude per phase channel. mmvk reads them as a
`custom` channel from a sidecar beside each BVH: `<clip>.<channel>.f32`, raw
little-endian float32 [source frames x dims] (docs/database.md). Here the
"model" is a stand-in computed in NumPy from the database's own foot
contacts (the phase runs 0 -> 1 between left-foot touchdowns); swap in your
model's output array.
"""
import argparse
import json
import pathlib
import shutil

import numpy as np

import mmvk

HERE = pathlib.Path(__file__).resolve().parent
DEFAULT_BVH = HERE.parents[1] / "crowd" / "data" / "cmu131"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--bvh", type=pathlib.Path, default=DEFAULT_BVH, help="a folder of BVH files")
parser.add_argument("--out", type=pathlib.Path, required=True, help="a folder for the BVH copies, sidecars and database")
args = parser.parse_args()

# The sidecars sit beside the BVH files, so work on copies.
args.out.mkdir(parents=True, exist_ok=True)
for bvh in sorted(args.bvh.glob("*.bvh")):
    shutil.copy(bvh, args.out / bvh.name)

# A first build at the files' own rate: one database frame per BVH frame.
plain = mmvk.build(args.out)


def phase_of(contacts):
    """Phase in cycles, 0 at each left touchdown, linear in between."""
    left = (contacts & 1) != 0
    touchdowns = np.flatnonzero(left[1:] & ~left[:-1]) + 1
    frames = np.arange(len(contacts))
    if len(touchdowns) < 2:
        return frames / 30.0  # no stride: one cycle a second
    return np.interp(frames, touchdowns, np.arange(len(touchdowns)), left=None, right=None) % 1.0


contacts = plain.animation.contacts
for clip in plain.clips:
    rows = slice(clip["first_frame"], clip["first_frame"] + clip["frame_count"])
    phase = phase_of(contacts[rows])
    amplitude = 1.0
    values = np.stack([amplitude * np.sin(2 * np.pi * phase), amplitude * np.cos(2 * np.pi * phase)], axis=1)
    sidecar = pathlib.Path(clip["source"]).with_suffix(".phase.f32")
    values.astype("<f4").tofile(sidecar)  # [source frames x 2], little-endian float32

# The default schema plus the sidecar channel.
schema = json.loads(plain.schema_json)
schema["channels"].append({"name": "phase", "kind": "custom", "dims": 2, "weight": 1.0})
db = mmvk.build(args.out, schema=schema)
db.save(args.out / "with-phase.mmdb")
channel = next(c for c in db.channels if c["name"] == "phase")
print(f"built {db} with channel {channel}")

# Frames at the same pose but half a cycle apart now differ in their cost.
search = mmvk.Search(db, "reference")
query = db.features[40:41].copy()
frames, costs = search.search(query, k=3)
print("nearest frames to frame 40:", frames[0].tolist(), "costs", np.round(costs[0], 3).tolist())
raw = db.raw(query)
o = channel["offset"]
raw[0, o:o + 2] *= -1  # the opposite phase
frames, costs = search.search(db.normalize(raw), k=3)
print("with the phase flipped:     ", frames[0].tolist(), "costs", np.round(costs[0], 3).tolist())
