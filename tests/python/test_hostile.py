"""Hostile and careless calls (issue 34): each is a clear TypeError or
ValueError naming the argument, never a crash, a hang or a lost recording."""
import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import mmvk
from conftest import CMU131


# Crashes: a None database was dereferenced (SIGSEGV).
def test_none_database_is_a_type_error(db):
    with pytest.raises(TypeError, match="db: expected an mmvk.Database, got None"):
        mmvk.Search(None)
    with pytest.raises(TypeError, match="db: expected an mmvk.Database, got None"):
        mmvk.Search(db=None, backend="fast-box")
    with pytest.raises(TypeError, match="db: expected an mmvk.Database, got None"):
        mmvk.Crowd(None, agents=2)


# Messages: "Unable to cast Python instance to C++ type" named nothing.
def test_search_arguments_are_named(db, queries):
    with pytest.raises(ValueError, match=r"threads: expected an integer from 0 to 4294967295, got -1"):
        mmvk.Search(db, "fast-box", threads=-1)
    with pytest.raises(TypeError, match=r"threads: expected an integer, got str"):
        mmvk.Search(db, "fast-box", threads="2")
    with pytest.raises(ValueError, match=r"device: expected an integer from 0 to 4294967295, got -1"):
        mmvk.Search(db, "fast-box", device=-1)
    with pytest.raises(ValueError, match=r"kmeans_seed: expected an integer from 0"):
        mmvk.Search(db, "clusters", kmeans_seed=2**64)
    with pytest.raises(TypeError, match=r"warm_up: expected True or False"):
        mmvk.Search(db, "fast-box", warm_up="yes")
    search = mmvk.Search(db, "fast-box", threads=np.int64(1))
    channel = db.channels[0]["name"]
    with pytest.raises(TypeError, match=rf"weights\['{channel}'\]: expected a number, got str"):
        search.search(queries, weights={channel: "2"})
    with pytest.raises(ValueError, match=rf"weights\['{channel}'\]: expected a finite number"):
        search.search(queries, weights={channel: float("nan")})
    # A NumPy integer is one frame for every query, as an int is.
    frames, _ = search.search(queries, continuing=np.int64(3))
    same, _ = search.search(queries, continuing=3)
    assert (frames == same).all()


def test_k_is_checked_before_the_results_are_allocated(db, queries):
    search = mmvk.Search(db, "fast-box")
    # 64 x (2**32 - 1) matches were allocated first: MemoryError.
    with pytest.raises(ValueError, match=r"k: expected 1 to 16, got 4294967295"):
        search.search(queries, k=2**32 - 1)


# Security: the OS reads a path only up to a NUL, so 'db.mmdb\0junk' loaded db.mmdb.
def test_paths_with_a_nul_are_refused(db, db_file, tmp_path):
    with pytest.raises(ValueError, match=r"path: the path holds a NUL byte at offset"):
        mmvk.Database.load(str(db_file) + "\0junk")
    with pytest.raises(ValueError, match=r"path: the path holds a NUL byte"):
        db.save(str(tmp_path / "e12") + "\0.mmdb")
    assert not (tmp_path / "e12").exists()


def test_a_path_that_is_not_utf8_reaches_the_file_system(db, tmp_path):
    name = os.fsdecode(b"caf\xe9.mmdb")  # a Latin-1 name, as os.listdir gives it
    db.save(tmp_path / name)
    assert os.path.exists(os.path.join(os.fsencode(tmp_path), b"caf\xe9.mmdb"))
    assert mmvk.Database.load(tmp_path / name).frame_count == db.frame_count
    with pytest.raises(OSError, match=r"missing-\\xe9\.mmdb: no such file"):
        mmvk.Database.load(tmp_path / os.fsdecode(b"missing-\xe9.mmdb"))


# Messages: fps=nan gave the JSON parser's raw error.
def test_build_fields_that_json_cannot_hold_are_named():
    with pytest.raises(ValueError, match=r"fps: expected a finite number, got nan"):
        mmvk.build(CMU131, fps=float("nan"))
    with pytest.raises(ValueError, match=r"the manifest fields: "):
        mmvk.build(CMU131, import_={"scale": float("inf")})


def manifest_text() -> str:
    return CMU131.read_text()


# The merge path (build(path, **fields)) parsed the file without the
# library's checks: duplicate keys and trailing bytes passed.
@pytest.mark.parametrize("mangle, message", [
    (lambda text: text.replace('"clips"', '"clips": [], "clips"', 1), r'duplicate key "clips"'),
    (lambda text: text.replace('"clips"', '"cl\\u0069ps": [], "clips"', 1), r'duplicate key "clips"'),
    (lambda text: text + "\0", r"a NUL byte at offset"),
    (lambda text: text + "{}", r"not valid JSON at byte \d+: .*expected end of input"),
])
def test_build_with_fields_is_as_strict_as_the_command_line(tmp_path, mangle, message):
    path = tmp_path / "manifest.json"
    text = mangle(manifest_text())  # refused before any clip is looked for
    path.write_text(text)
    with pytest.raises(ValueError, match=message):
        mmvk.build(path, mirror=True)
    with pytest.raises(ValueError, match=message):
        mmvk.build(path)


# Crashes: the merge path dumped a deeply nested document recursively
# (stack overflow); every path now stops at kMaxJsonDepth.
def test_deep_nesting_is_refused_before_any_walk(tmp_path):
    manifest = json.loads(manifest_text())
    path = tmp_path / "deep.json"
    deep = "[" * 100000 + "]" * 100000
    text = manifest_text()
    path.write_text(text[: text.rfind("}")] + f', "schema": {deep}}}')
    for call in (lambda: mmvk.build(path, fps=30), lambda: mmvk.build(path)):
        with pytest.raises(ValueError, match=r"nested more than 256 levels deep"):
            call()
    assert manifest["clips"]


def test_json_errors_give_the_byte_offset_and_reason(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{"fps": 1e400}')
    with pytest.raises(ValueError, match=r"bad.json: not valid JSON at byte 1[0-9]: number overflow parsing '1e400'"):
        mmvk.build(path)


# Crashes: summary() from a thread while another stepped aborted with
# "double free or corruption"; two threads stepping lost ticks.
def test_crowd_calls_from_several_threads_take_turns(db):
    crowd = mmvk.Crowd(db, agents=8, record=True)
    errors = []
    done = threading.Event()

    def reader():
        try:
            while not done.is_set():
                crowd.summary()
                assert crowd.joint_positions.shape[0] == 8
                _ = crowd.time, crowd.root_positions, repr(crowd)
        except Exception as error:  # noqa: BLE001 - reported below
            errors.append(error)

    def stepper():
        try:
            for _ in range(40):
                crowd.step()
        except Exception as error:  # noqa: BLE001
            errors.append(error)

    threads = [threading.Thread(target=reader) for _ in range(2)] + [threading.Thread(target=stepper) for _ in range(2)]
    for t in threads:
        t.start()
    crowd.run(1.0)
    for t in threads[2:]:
        t.join()
    done.set()
    for t in threads[:2]:
        t.join()
    assert not errors, errors
    assert crowd.ticks == 80 + round(1.0 * crowd.rate)


# Hangs: run() released the GIL and never checked for signals, so Ctrl-C
# could not stop run(1e9).
def test_ctrl_c_stops_a_long_run(db):
    crowd = mmvk.Crowd(db, agents=2)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            crowd.run(300000.0)  # 9 million ticks: hours
    finally:
        timer.cancel()
    assert time.monotonic() - start < 10.0
    assert 0 < crowd.ticks < 9_000_000
    crowd.step()  # the crowd stays usable


# Data loss: one failed write_html ended the recording, so every retry
# failed with "the recording was already written".
def test_a_failed_write_html_can_be_retried(db, tmp_path):
    crowd = mmvk.Crowd(db, agents=3, record=True)
    with pytest.raises(OSError, match="nothing was recorded yet"):
        crowd.write_html(tmp_path / "early.html")
    for _ in range(10):
        crowd.step()
    with pytest.raises(OSError):
        crowd.write_html(tmp_path / "missing-folder" / "crowd.html")
    first = crowd.write_html(tmp_path / "crowd.html")
    assert first > 1000
    assert crowd.write_html(tmp_path / "again.html") == first
    assert (tmp_path / "crowd.html").read_bytes() == (tmp_path / "again.html").read_bytes()


# Messages: Animation.parents was a writable copy where the docs promise
# read-only views.
def test_parents_are_a_read_only_view(db):
    parents = db.animation.parents
    assert parents.dtype == np.int32 and parents[0] == -1
    with pytest.raises(ValueError):
        parents[0] = 3


# Messages: a float32 dtype with metadata was refused as "expected a
# float32 array, got float32"; a byte-swapped one stays refused.
def test_float32_with_metadata_is_float32(db, queries):
    search = mmvk.Search(db, "fast-box")
    tagged = queries.view(np.dtype(np.float32, metadata={"units": "normalized"}))
    frames, _ = search.search(tagged)
    assert (frames == search.search(queries)[0]).all()
    with pytest.raises(ValueError, match="expected a float32 array"):
        search.search(queries.astype(">f4"))


# Messages: a 1e30 velocity overflowed the search's costs later, as
# "search: query 0: its costs could overflow float", naming neither.
def test_a_huge_desired_velocity_names_its_row(db):
    crowd = mmvk.Crowd(db, agents=3)
    velocity = np.zeros((3, 2), np.float32)
    velocity[1] = (1e30, 0.0)
    with pytest.raises(ValueError, match=r"desired_velocity\[1\]: 1e\+30 m/s is over 1000 m/s"):
        crowd.step(velocity)
    crowd.step(np.ones((3, 2), np.float32))
