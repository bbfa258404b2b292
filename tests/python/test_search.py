"""Search.search against `mmvk query`: the same frames and costs, bit for bit,
for every CPU backend and for vulkan-brute (lavapipe in CI)."""
import subprocess

import numpy as np
import pytest

import mmvk
from conftest import vulkan_required

K = 4
CPU_BACKENDS = ["reference", "fast-brute", "fast-box", "clusters", "clusters-nprobe"]


def cli_query(cli, db_file, queries, tmp_path, backend, extra=()):
    q = tmp_path / "q.f32"
    queries.astype("<f4").tofile(q)
    out = tmp_path / "results.tsv"
    subprocess.run([str(cli), "query", str(db_file), "--queries", str(q), "--normalized", "--backend", backend,
                    "--k", str(K), "--out", str(out), *extra], check=True, capture_output=True)
    frames = np.full((len(queries), K), -1, np.int64)
    costs = np.full((len(queries), K), np.inf, np.float32)
    for line in out.read_text().splitlines():
        if line.startswith("#"):
            continue
        cells = line.split("\t")
        b = int(cells[0])
        for r, cell in enumerate(cells[1:]):
            if cell != "none":
                frame, cost = cell.split(":")
                frames[b, r] = int(frame)
                costs[b, r] = np.float32(float(cost))
    return frames, costs


def make_search(db, backend):
    try:
        return mmvk.Search(db, backend)
    except ValueError as error:
        # Only a missing Vulkan device may skip, and not in CI.
        if backend.startswith("vulkan") and not vulkan_required():
            pytest.skip(f"no Vulkan device: {error}")
        raise


@pytest.mark.parametrize("backend", CPU_BACKENDS + ["vulkan-brute"])
def test_search_equals_mmvk_query(backend, db, db_file, queries, cli, tmp_path):
    if backend not in mmvk.backends():
        pytest.skip(f"{backend} is not built")
    search = make_search(db, backend)
    frames, costs = search.search(queries, k=K)
    assert frames.shape == (len(queries), K) and frames.dtype == np.int64
    assert costs.shape == (len(queries), K) and costs.dtype == np.float32
    want_frames, want_costs = cli_query(cli, db_file, queries, tmp_path, backend)
    np.testing.assert_array_equal(frames, want_frames)
    np.testing.assert_array_equal(costs, want_costs)


@pytest.mark.parametrize("backend", ["reference", "clusters"])
def test_query_options_equal_mmvk_query(backend, db, db_file, queries, cli, tmp_path):
    search = mmvk.Search(db, backend)
    frames, costs = search.search(queries, k=K, continuing=100, require=["walk"], exclude=["turn"],
                                  weights={"trajectory_position": 2.0, "hip_velocity": 0.5},
                                  continuing_bias=-0.5, continuing_multiplier=0.75, exclusion_window=3)
    want = cli_query(cli, db_file, queries, tmp_path, backend,
                     ["--continuing", "100", "--require", "walk", "--exclude", "turn",
                      "--weights", "trajectory_position=2,hip_velocity=0.5", "--continuing-bias", "-0.5",
                      "--continuing-multiplier", "0.75", "--exclusion-window", "3"])
    np.testing.assert_array_equal(frames, want[0])
    np.testing.assert_array_equal(costs, want[1])


def test_per_query_continuing_frames(db, queries):
    search = mmvk.Search(db, "reference")
    continuing = np.arange(len(queries), dtype=np.int64)
    continuing[::2] = -1
    frames, costs = search.search(queries, continuing=continuing, continuing_bias=-1e6)
    # A huge bonus makes the continuing frame win wherever there is one.
    assert np.all(frames[1::2, 0] == continuing[1::2])
    plain = search.search(queries[::2])
    np.testing.assert_array_equal(frames[::2], plain[0])


def test_raw_and_normalize_are_inverse(db):
    rows = db.features[:16]
    raw = db.raw(rows)
    assert raw.shape == rows.shape and raw.dtype == np.float32
    np.testing.assert_allclose(db.normalize(raw), rows, atol=1e-4)
    assert db.normalize(raw[0]).shape == (db.dims,)


def test_backends_lists_the_cpu_ones():
    names = mmvk.backends()
    for name in CPU_BACKENDS:
        assert name in names
