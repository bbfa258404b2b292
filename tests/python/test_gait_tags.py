"""Crowd.set_tags: a host changes a character's gait at runtime. Told to
stand on the shipped set's standing loops (tagged "stand" by its manifest,
all of them measured 'gait:stand') the characters stand with their toes
still; told to walk again, they walk. Refused calls name the field and
change nothing. ('gait:stand' alone also takes the takes' swaying stands:
toes 0.12 m/s median on cmu-walks.)"""
import numpy as np
import pytest

import mmvk

AGENTS = 8


def share_tagged(db, frames, tag):
    bit = np.uint64(1) << np.uint64(db.tags.index(tag))
    return float(np.mean((db.frame_tags[frames] & bit) != 0))


def toe_joints(crowd):
    names = crowd.skeleton["names"]
    return [i for i, name in enumerate(names) if "toe" in name.lower()]


def test_a_host_changes_a_characters_gait_at_runtime(db):
    crowd = mmvk.Crowd(db, agents=AGENTS, seed=2)
    toes = toe_joints(crowd)
    assert len(toes) == 2
    walk = np.tile(np.array([[0.0, 1.3]], np.float32), (AGENTS, 1))
    still = np.zeros((AGENTS, 2), np.float32)
    crowd.set_tags(np.arange(AGENTS), require=["gait:walk"])
    for _ in range(60):
        crowd.step(walk)
    assert share_tagged(db, crowd.frames, "gait:walk") >= 0.9

    crowd.set_tags(range(AGENTS), require=["stand"])
    speeds = []
    for tick in range(120):
        before = crowd.joint_positions[:, toes].copy()
        crowd.step(still)
        if tick >= 60:  # after the stop has settled
            speeds.append(np.linalg.norm(crowd.joint_positions[:, toes] - before, axis=-1) / crowd.dt)
    assert share_tagged(db, crowd.frames, "gait:stand") == 1.0
    assert np.median(speeds) < 0.01, "toes move while standing"
    assert np.percentile(speeds, 90) < 0.02

    crowd.set_tags(range(AGENTS), require=["gait:walk"])
    for _ in range(60):
        crowd.step(walk)
    assert share_tagged(db, crowd.frames, "gait:walk") >= 0.9


def test_set_tags_errors_name_the_field_and_change_nothing(db):
    told = mmvk.Crowd(db, agents=4, seed=5)
    never = mmvk.Crowd(db, agents=4, seed=5)
    with pytest.raises(ValueError, match=r"require: unknown tag 'gait:fly'.*gait:stand"):
        told.set_tags(0, require=["gait:fly"])
    with pytest.raises(ValueError, match="agents: 4 is not a character of this crowd"):
        told.set_tags([1, 4], require=["gait:walk"])
    with pytest.raises(ValueError, match="agents: -1 is not a character"):
        told.set_tags(-1, require=["gait:walk"])
    with pytest.raises(ValueError, match="a tag is both required and excluded"):
        told.set_tags(0, require=["gait:walk"], exclude=["gait:walk"])
    with pytest.raises(ValueError, match="require: expected a list of tag names"):
        told.set_tags(0, require="gait:walk")
    for _ in range(30):
        told.step()
        never.step()
    assert np.array_equal(told.frames, never.frames)
