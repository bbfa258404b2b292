#!/usr/bin/env python3
"""A host's scripted commands through mmvk.Crowd.step, and how closely the
characters follow them: the measurement of bench/RESULTS.md, "Speed from the
animation".

16 characters, 4 m apart, each given the same script of desired velocities
(stand, walk 1.3 m/s, turn 90 degrees, walk 0.8, run 3.0, turn 180 degrees
at 1.3, stop, walk 0.8). Prints one JSON object: the summary's figures
(glide, speed and heading errors, trajectory error, sliding, pose
acceleration, jumps) and, per commanded speed, the played and shown root
speeds over the held part of each segment (from 1 s after its command);
for a stand, the share of its held agent-ticks with the root and both toes
under 5 cm/s (still_share); and for every segment the time it took to
settle (settle_s): from the first tick after which, to the segment's end,
every character's shown speed over the last 0.5 s is within 10% of the
command (a stand: under 5 cm/s) and its heading within 10 degrees; for a
stand, the mean distance the shown root travelled from the command
(stop_travel_m) against the simulated root's (spring_travel_m: the spring's
own overshoot), and where it came to rest against it (rest_offset_m). The
planted feet's distance from the animated pose (foot_corrections of locked
feet): p95 over the whole run (planted_offset_p95_m) and, per stand, over
its held part (rest_planted_offset_p95_m); null with a module that lacks
foot_corrections.

  PYTHONPATH=build/python python3 bench/tools/command_script.py DATA [--rate 30] [--speed-from-animation off]
      [--correction-half-life S]

DATA: a manifest.json or a .mmdb. Works with a module that lacks
root_corrections (main before speed from the animation): its played speeds
are then null.
"""
import argparse
import json
import math

import numpy as np

import mmvk

AGENTS = 16
# (seconds, speed m/s, heading degrees): the heading turns at the segment's start.
SCRIPT = [(2.0, 0.0, 0.0), (4.0, 1.3, 0.0), (4.0, 1.3, 90.0), (4.0, 0.8, 90.0), (4.0, 3.0, 90.0),
          (4.0, 1.3, 270.0), (3.0, 0.0, 270.0), (4.0, 0.8, 270.0)]
SETTLE_S = 1.0
WINDOW_S = 0.5  # the shown speed that settling is judged on: path length over this long


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("data")
    parser.add_argument("--rate", type=float, default=30.0)
    parser.add_argument("--speed-from-animation", default="on", choices=["on", "off"])
    parser.add_argument("--correction-half-life", type=float, default=None)
    args = parser.parse_args()
    db = mmvk.Database.load(args.data) if args.data.endswith(".mmdb") else mmvk.build(args.data)
    kwargs = {} if args.speed_from_animation == "on" else {"speed_from_animation": False}
    if args.correction_half_life is not None:
        kwargs["correction_half_life"] = args.correction_half_life
    crowd = mmvk.Crowd(db, agents=AGENTS, backend="fast-box", rate=args.rate, seed=1, **kwargs)
    for i in range(AGENTS):
        crowd.place(i, 4.0 * i, 0.0, 0.0)
    has_corrections = hasattr(crowd, "root_corrections")
    has_foot_corrections = hasattr(crowd, "foot_corrections")
    planted_offsets = []  # per tick, the locked feet's distances from their animated pose
    toes = [j for j in db.animation.contact_joints if j >= 0]
    segments = []
    last = crowd.root_positions.copy()
    last_toes = crowd.joint_positions[:, toes].copy()
    for seconds, speed, heading in SCRIPT:
        h = math.radians(heading)
        velocity = np.tile(np.array([speed * math.sin(h), speed * math.cos(h)], np.float32), (AGENTS, 1))
        facing = np.full(AGENTS, h, np.float32)
        ticks = int(round(seconds * crowd.rate))
        shown = played = held = 0.0
        still = steady = 0
        # A stop: how far the shown and the simulated roots travel after the command (the spring's own
        # overshoot is the latter), and where the shown root comes to rest against the simulated one.
        start_shown, start_simulated = crowd.root_positions.copy(), crowd.simulated_positions.copy()
        recent = []
        rest_offsets = []
        following = []  # per tick: the mean shown speed within 10% (stops: under 5 cm/s) and heading within 10 degrees
        for tick in range(ticks):
            crowd.step(velocity, facing)
            roots = crowd.root_positions
            step = np.hypot(*(roots - last)[:, [0, 2]].T)
            toe_positions = crowd.joint_positions[:, toes]
            toe_speed = np.linalg.norm(toe_positions - last_toes, axis=2).max(axis=1) / crowd.dt
            last_toes = toe_positions.copy()
            if has_foot_corrections:
                corrections = crowd.foot_corrections
                offsets = np.hypot(corrections[..., 0], corrections[..., 2])[crowd.foot_locked == 1]
                planted_offsets.append(offsets)
                if speed == 0.0 and tick * crowd.dt >= SETTLE_S:
                    rest_offsets.append(offsets)
            recent.append(step)
            window = recent[-int(round(WINDOW_S * crowd.rate)):]
            shown_speed = np.sum(window, axis=0) / (len(window) * crowd.dt)
            yaw_error = np.degrees(np.abs(np.angle(np.exp(1j * (crowd.root_yaws - h)))))
            if speed == 0.0:
                following.append(bool(np.all(shown_speed < 0.05)))
            else:
                following.append(bool(np.all(np.abs(shown_speed / speed - 1) < 0.1) and np.all(yaw_error < 10)))
            if tick * crowd.dt >= SETTLE_S:
                if speed == 0.0:
                    steady += AGENTS
                    still += int(np.count_nonzero((step / crowd.dt < 0.05) & (toe_speed < 0.05)))
                held += crowd.dt
                shown += step.mean()
                if has_corrections:
                    own = (roots - last - crowd.root_corrections)[:, [0, 2]]
                    played += np.hypot(*own.T).mean()
            last = roots.copy()
        # Settled: from the first tick after which the crowd follows to the segment's end (null: never).
        settled = next((i for i in range(len(following)) if all(following[i:])), None)
        stop = {}
        if speed == 0.0:
            flat = lambda p: p[:, [0, 2]]
            stop = {"stop_travel_m": round(float(np.linalg.norm(flat(crowd.root_positions - start_shown), axis=1).mean()), 3),
                    "spring_travel_m": round(float(np.linalg.norm(flat(crowd.simulated_positions - start_simulated), axis=1).mean()), 3),
                    "rest_offset_m": round(float(np.linalg.norm(flat(crowd.root_positions - crowd.simulated_positions), axis=1).mean()), 3),
                    "rest_planted_offset_p95_m": p95(rest_offsets) if has_foot_corrections else None}
        segments.append({"speed_mps": speed, "heading_deg": heading, **stop,
                         "settle_s": None if settled is None else round(settled * crowd.dt, 2),
                         "still_share": round(still / steady, 3) if steady else None,
                         "shown_mps": round(shown / held, 3),
                         "played_mps": round(played / held, 3) if has_corrections else None})
    s = crowd.summary()
    keys = ["trajectory_error_m_1s", "foot_sliding_cm_s", "foot_sliding_before_ik_cm_s", "pose_acceleration_p99_m_s2",
            "transitions_per_agent_s", "glide_cm_s", "glide_share_of_travel", "animation_share_of_travel",
            "played_speed_error", "shown_speed_error", "heading_error_deg", "standing_still_share", "chosen_frames_hash"]
    print(json.dumps({"data": args.data, "rate": args.rate, "speed_from_animation": args.speed_from_animation,
                      "summary": {k: s.get(k) for k in keys},
                      "planted_offset_p95_m": p95(planted_offsets) if has_foot_corrections else None,
                      "segments": segments}))


def p95(per_tick):
    """The 95th percentile of the distances in a list of per-tick arrays, metres (null when none)."""
    values = np.concatenate(per_tick) if per_tick else np.zeros(0)
    return round(float(np.percentile(values, 95)), 3) if values.size else None


if __name__ == "__main__":
    main()
