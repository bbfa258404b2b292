#!/usr/bin/env python3
"""Build a motion matching database from a folder of BVH files and query it.

    PYTHONPATH=build/python python3 host/examples/python/build_and_query.py [--bvh DIR] [--out DIR]

Builds the database (default: the crowd's CMU subject 131 walks), saves it,
asks for the frames whose future trajectory turns left, and prints them.
"""
import argparse
import pathlib

import numpy as np

import mmvk

HERE = pathlib.Path(__file__).resolve().parent
DEFAULT_BVH = HERE.parents[1] / "crowd" / "data" / "cmu131"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--bvh", type=pathlib.Path, default=DEFAULT_BVH, help="a folder of BVH files")
parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("."), help="where walks.mmdb is written")
args = parser.parse_args()

# Every BVH in the folder, resampled to 30 fps, each with a mirrored copy.
db = mmvk.build(args.bvh, fps=30, mirror=True)
args.out.mkdir(parents=True, exist_ok=True)
db.save(args.out / "walks.mmdb")
print(f"built {db}: {len(db.clips)} clips, channels {[c['name'] for c in db.channels]}")

# A query in raw units: start from a frame's own features (feet, hips) and
# ask for a trajectory that curves to the left (+x is the character's left,
# +z its facing; metres at 1/3, 2/3 and 1 s).
raw = db.raw(db.features[100])
traj = next(c for c in db.channels if c["name"] == "trajectory_position")
curve = np.array([[0.05, 0.2], [0.2, 0.4], [0.45, 0.55]], np.float32)
raw[traj["offset"]:traj["offset"] + traj["dims"]] = curve.ravel()
query = db.normalize(raw)[np.newaxis, :]

search = mmvk.Search(db, "clusters")
frames, costs = search.search(query, k=4)
for frame, cost in zip(frames[0], costs[0]):
    clip = db.clips[db.frame_clip[frame]]
    print(f"frame {frame:5d}  cost {cost:7.3f}  clip {clip['name']}  tags {clip['tags']}")
