"""Shared fixtures of the Python module's tests (tests/python, run by ctest as `python`).

The data is the crowd's shipped CMU subject 131 walks (host/crowd/data/cmu131):
small enough to build in well under a second. The command line (`mmvk`) is
found through $MMVK_CLI, which ctest sets, else beside the module in the build tree.
"""
import os
import pathlib

import numpy as np
import pytest

import mmvk

REPO = pathlib.Path(__file__).resolve().parents[2]
CMU131 = REPO / "host" / "crowd" / "data" / "cmu131" / "manifest.json"


def cli_path() -> pathlib.Path:
    if "MMVK_CLI" in os.environ:
        return pathlib.Path(os.environ["MMVK_CLI"])
    return pathlib.Path(mmvk.__file__).resolve().parents[1] / "host" / "mmvk"


@pytest.fixture(scope="session")
def cli() -> pathlib.Path:
    path = cli_path()
    if not path.exists():
        pytest.fail(f"the mmvk command line is not at {path} (set MMVK_CLI)")
    return path


@pytest.fixture(scope="session")
def db() -> mmvk.Database:
    return mmvk.build(CMU131)


@pytest.fixture(scope="session")
def db_file(db, tmp_path_factory) -> pathlib.Path:
    path = tmp_path_factory.mktemp("db") / "cmu131.mmdb"
    db.save(path)
    return path


@pytest.fixture(scope="session")
def queries(db) -> np.ndarray:
    """64 normalized queries near database rows (fixed seed), so that results are unique."""
    rng = np.random.default_rng(7)
    rows = rng.choice(db.frame_count, size=64, replace=False)
    noise = rng.normal(0.0, 0.3, size=(64, db.dims)).astype(np.float32)
    return np.ascontiguousarray(db.features[rows] + noise, dtype=np.float32)


def vulkan_required() -> bool:
    return os.environ.get("MMVK_REQUIRE_VULKAN", "") not in ("", "0")
