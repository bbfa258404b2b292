#!/usr/bin/env python3
"""Where a crowd's planted feet slide: splits the sliding of an
`mmvk crowd --trace FILE --trace-agents M` recording by its cause.

The sliding is measured as the crowd measures it (host/crowd/measure/motion_meter.hpp):
between two ticks where the foot is flagged planted, the horizontal speed of
its point on the ground, the ankle while only the heel bit is set, else the
toe. It is split two ways:
  - by tick kind: the point stays the toe, stays the heel, or switches
    between them (a toe rolling down after a heel strike moves as it lands),
    and whether foot IK held the foot at both ticks;
  - for held toes, by how far the leg is stretched: hip-to-ankle distance over
    thigh + shin length at the later tick (the IK softens its reach from 95%).
Each line gives the share of samples, their mean speed and what they add to
the overall mean (cm/s), so the contributions sum to the crowd's figure.

usage: bench/trace_sliding.py FILE   (FILE.json beside it; needs numpy)
"""
import json
import sys

import numpy as np


def main(path):
    side_car = json.load(open(path + ".json"))
    ticks, agents, joints, _ = side_car["shape"]
    dt = 1.0 / side_car["tick_rate_hz"]
    positions = np.fromfile(path, dtype="<f4").reshape(ticks, agents, joints, 3)
    contacts = np.array(side_car["contacts"])
    locks = np.array(side_car["foot_locks"])
    parents = side_car["parents"]
    bits = side_car["contact_bits"]

    kinds = {}  # kind -> [samples, summed speed]
    stretch_edges = [0.0, 0.9, 0.95, 0.98, 2.0]
    stretch = [[0, 0.0] for _ in stretch_edges[:-1]]
    samples = 0
    total = 0.0
    for foot, side in enumerate(["left", "right"]):
        toe = side_car["contact_joints"][foot]
        ankle = parents[toe]
        knee = parents[ankle]
        hip = parents[knee]
        planted = (contacts & bits[side]) > 0
        heel_only = ((contacts & bits[side + "_heel"]) > 0) & ~((contacts & bits[side + "_toe"]) > 0)
        held = ((locks >> foot) & 1) > 0
        both = planted[1:] & planted[:-1]
        point_heel = heel_only[1:]
        step_toe = np.linalg.norm((positions[1:, :, toe] - positions[:-1, :, toe])[..., [0, 2]], axis=-1) / dt
        step_heel = np.linalg.norm((positions[1:, :, ankle] - positions[:-1, :, ankle])[..., [0, 2]], axis=-1) / dt
        speed = np.where(point_heel, step_heel, step_toe)
        switched = heel_only[1:] != heel_only[:-1]
        held_both = held[1:] & held[:-1]
        for name, mask in [
            ("toe", ~point_heel & ~switched),
            ("heel", point_heel & ~switched),
            ("heel <-> toe switch", switched),
        ]:
            for suffix, lock_mask in [("", held_both), (", not held", ~held_both)]:
                m = both & mask & lock_mask
                entry = kinds.setdefault(name + suffix, [0, 0.0])
                entry[0] += int(m.sum())
                entry[1] += float(speed[m].sum())
        leg = np.linalg.norm(positions[:, :, hip] - positions[:, :, knee], axis=-1) + np.linalg.norm(
            positions[:, :, knee] - positions[:, :, ankle], axis=-1)
        extension = (np.linalg.norm(positions[:, :, hip] - positions[:, :, ankle], axis=-1) / leg)[1:]
        held_toe = both & ~point_heel & ~switched & held_both
        for i in range(len(stretch)):
            m = held_toe & (extension >= stretch_edges[i]) & (extension < stretch_edges[i + 1])
            stretch[i][0] += int(m.sum())
            stretch[i][1] += float(step_toe[m].sum())
        samples += int(both.sum())
        total += float(speed[both].sum())

    if samples == 0:
        sys.exit(f"{path}: no foot is planted at two ticks in a row")
    print(f"{path}: {samples} planted foot-tick pairs, sliding {100 * total / samples:.2f} cm/s")
    print("by tick kind (share of samples, mean cm/s, adds cm/s):")
    for name, (count, summed) in kinds.items():
        if count:
            print(f"  {name:30s} {count / samples:7.1%} {100 * summed / count:8.2f} {100 * summed / samples:7.2f}")
    print("held toes by leg extension (share of samples, mean cm/s, adds cm/s):")
    for i, (count, summed) in enumerate(stretch):
        if count:
            label = f"{stretch_edges[i]:.0%} to {min(stretch_edges[i + 1], 1.0):.0%}"
            print(f"  {label:30s} {count / samples:7.1%} {100 * summed / count:8.2f} {100 * summed / samples:7.2f}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
