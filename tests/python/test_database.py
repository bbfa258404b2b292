"""Database: zero-copy arrays, build options, load/save, and errors that carry the library's message."""
import numpy as np
import pytest

import mmvk
from conftest import CMU131


def test_features_share_the_database_memory(db):
    first, second = db.features, db.features
    assert first.shape == (db.frame_count, db.dims) and first.dtype == np.float32
    # Two views of the same buffer: no copy was made for either.
    assert first.__array_interface__["data"][0] == second.__array_interface__["data"][0]
    assert np.shares_memory(first, second)
    assert not first.flags.owndata and first.base is db
    assert not first.flags.writeable
    with pytest.raises(ValueError):
        first[0, 0] = 1.0


def test_views_keep_the_database_alive():
    features = mmvk.build(CMU131).features  # the Database lives on in the view's base
    assert np.isfinite(features).all()


def test_metadata(db):
    # The manifest's tags, then the ones the build measures (docs/database.md, "Gait tags, measured").
    assert db.tags == ["walk", "straight", "turn", "stand",
                       "gait:stand", "gait:walk", "gait:jog", "gait:run", "gait:start", "gait:stop"]
    assert sum(c["dims"] for c in db.channels) == db.dims
    assert len(db.dim_names) == db.dims
    clips = db.clips
    assert clips[0]["first_frame"] == 0
    assert sum(c["frame_count"] for c in clips) == db.frame_count
    assert db.frame_flags.shape == (db.frame_count,) and db.frame_flags.dtype == np.uint32
    assert db.frame_clip[-1] == len(clips) - 1


def test_animation_arrays(db):
    a = db.animation
    joints = len(a.joint_names)
    assert a.rotations.shape == (db.frame_count, joints, 4)
    np.testing.assert_allclose(np.linalg.norm(a.rotations, axis=2), 1.0, atol=1e-4)
    assert a.root_positions.shape == (db.frame_count, 3) and np.all(a.root_positions[:, 1] == 0)
    assert a.root_yaws.shape == (db.frame_count,)
    assert a.contacts.shape == (db.frame_count,) and a.contacts.dtype == np.uint8
    assert a.parents[0] == -1 and np.all(a.parents[1:] < np.arange(1, joints))
    assert np.shares_memory(a.rotations, db.animation.rotations)


def test_save_and_load(db, tmp_path):
    path = tmp_path / "db.mmdb"
    db.save(path)
    loaded = mmvk.Database.load(str(path))
    assert loaded.content_hash == db.content_hash
    np.testing.assert_array_equal(loaded.features, db.features)


def test_build_fields_override_the_manifest(db):
    at_60 = mmvk.build(CMU131, fps=60)
    assert at_60.fps == 60 and at_60.frame_count > 1.9 * db.frame_count
    folder = mmvk.build(CMU131.parent, fps=30, mirror=True)
    assert len(folder.clips) == 16 and folder.clips[1]["mirrored"]



def test_build_one_bvh_file(monkeypatch):
    bvh = CMU131.parent / "131_01.bvh"
    one = mmvk.build(bvh)
    assert len(one.clips) == 1 and one.clips[0]["name"] == "131_01"
    # With fields, and a path relative to the working directory.
    monkeypatch.chdir(CMU131.parent.parent)
    at_15 = mmvk.build("cmu131/131_01.bvh", fps=15, mirror=True)
    assert at_15.fps == 15 and len(at_15.clips) == 2 and at_15.clips[1]["mirrored"]

def test_build_with_a_schema_dict(db):
    schema = {"channels": [{"name": "trajectory_position", "kind": "trajectory_position",
                            "offsets_seconds": [0.5, 1.0]}]}
    small = mmvk.build(CMU131, schema=schema)
    assert small.dims == 4 and small.frame_count == db.frame_count


@pytest.mark.parametrize("call, error, message", [
    (lambda db: mmvk.Database.load("/nonexistent/db.mmdb"), OSError, "/nonexistent/db.mmdb"),
    (lambda db: mmvk.build("/nonexistent/walks"), OSError, "/nonexistent/walks"),
    (lambda db: mmvk.build(CMU131, fps="fast"), ValueError, "fps"),
    (lambda db: mmvk.build(CMU131, edge_rule="wrap"), ValueError, "edge_rule"),
    (lambda db: db.raw(db.features[:2].astype(np.float64)), ValueError, "float32"),
])
def test_errors(db, call, error, message):
    with pytest.raises(error, match=message):
        call(db)


def test_a_corrupt_file_is_a_value_error(tmp_path):
    path = tmp_path / "bad.mmdb"
    path.write_bytes(b"MMVKDB\n\0" + b"\0" * 40)
    with pytest.raises(ValueError, match="bad.mmdb"):
        mmvk.Database.load(path)
