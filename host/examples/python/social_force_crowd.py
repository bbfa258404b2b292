#!/usr/bin/env python3
"""A social-force crowd in NumPy that steers mmvk's motion-matched characters.

    PYTHONPATH=build/python python3 host/examples/python/social_force_crowd.py --agents 40 --seconds 30 --html crowd.html

Two groups cross a square, each character heading for the far side. The
steering is Helbing and Molnar's social force model (a drive toward the
goal plus exponential repulsion from neighbours), written below in NumPy;
mmvk.Crowd animates the characters along the velocities it asks for, and
writes the viewer page.
"""
import argparse
import json
import pathlib

import numpy as np

import mmvk

HERE = pathlib.Path(__file__).resolve().parent
DEFAULT_DATA = HERE.parents[1] / "crowd" / "data" / "cmu131" / "manifest.json"

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--data", type=pathlib.Path, default=DEFAULT_DATA, help="a manifest, BVH folder or .mmdb")
parser.add_argument("--agents", type=int, default=40)
parser.add_argument("--seconds", type=float, default=30.0)
parser.add_argument("--backend", default="clusters")
parser.add_argument("--seed", type=int, default=1)
parser.add_argument("--html", type=pathlib.Path, help="write the viewer page here")
parser.add_argument("--summary", type=pathlib.Path, help="write the run's figures (JSON) here")
args = parser.parse_args()

db = mmvk.Database.load(args.data) if args.data.suffix == ".mmdb" else mmvk.build(args.data)

# Two groups on opposite sides of a square, each walking to the other side.
rng = np.random.default_rng(args.seed)
n, half = args.agents, 5.0
side = np.where(np.arange(n) % 2 == 0, -1.0, 1.0)
start = np.stack([side * half, rng.uniform(-half, half, n)], axis=1)
goal = np.stack([-side * half, rng.uniform(-half, half, n)], axis=1)
scenario = {"world_size_m": 2 * half + 4,
            "agents": [{"start": s.tolist(), "goals": [g.tolist()]} for s, g in zip(start, goal)]}

crowd = mmvk.Crowd(db, scenario=scenario, backend=args.backend, record=args.html is not None,
                   title=f"{n} agents \u00b7 social force (NumPy) \u00b7 {args.backend}")


def social_force(pos, vel, goal, speed, dt, tau=0.5, a=2.0, b=0.3, radius=0.3):
    """One step of the social force model: returns the new velocities [n x 2]."""
    to_goal = goal - pos
    dist = np.linalg.norm(to_goal, axis=1, keepdims=True)
    wanted = np.where(dist > 0.5, speed * to_goal / np.maximum(dist, 1e-6), 0.0)
    force = (wanted - vel) / tau  # drive toward the preferred velocity
    diff = pos[:, None, :] - pos[None, :, :]  # [n x n x 2], from j to i
    d = np.linalg.norm(diff, axis=2)
    np.fill_diagonal(d, np.inf)
    push = a * np.exp((2 * radius - d) / b)  # exponential repulsion
    force += np.sum((push / np.maximum(d, 1e-6))[:, :, None] * diff, axis=1)
    vel = vel + dt * force
    # No faster than the motion capture can walk.
    v = np.linalg.norm(vel, axis=1, keepdims=True)
    return vel * np.minimum(1.0, 1.3 * speed / np.maximum(v, 1e-6))


speed = crowd.walk_speed
vel = np.zeros((n, 2))
for _ in range(int(round(args.seconds * crowd.rate))):
    pos = crowd.root_positions[:, [0, 2]].astype(np.float64)  # (x, z) of each character as animated
    vel = social_force(pos, vel, goal, speed, crowd.dt)
    crowd.step(vel.astype(np.float32))

summary = crowd.summary()
reached = np.linalg.norm(crowd.root_positions[:, [0, 2]] - goal, axis=1) < 1.0
print(f"{n} characters, {summary['seconds']:.1f} s on {summary['backend']}: {reached.sum()} at their goals, "
      f"trajectory error at 1 s {summary['trajectory_error_m_1s']:.3f} m, "
      f"foot sliding {summary['foot_sliding_cm_s']:.2f} cm/s, {summary['transitions_per_agent_s']:.2f} jumps/s")
if args.summary:
    args.summary.write_text(json.dumps(summary, indent=2))
if args.html:
    print(f"viewer page: {args.html} ({crowd.write_html(args.html):,} bytes)")
