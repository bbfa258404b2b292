"""Bad input raises ValueError (or OSError for files) with the library's message."""
import numpy as np
import pytest

import mmvk


@pytest.fixture(scope="module")
def search(db):
    return mmvk.Search(db, "fast-box")


def test_wrong_dtype(search, queries):
    with pytest.raises(ValueError, match="expected a float32 array, got float64"):
        search.search(queries.astype(np.float64))


def test_wrong_shape(search, queries, db):
    with pytest.raises(ValueError, match=rf"expected shape \(B, {db.dims}\), got \(64, 5\)"):
        search.search(queries[:, :5])
    with pytest.raises(ValueError, match="expected shape"):
        search.search(queries[0])


def test_nan_names_the_query_and_feature(search, queries):
    bad = queries.copy()
    bad[3, 2] = np.nan
    # The library's own message (validate_search).
    with pytest.raises(ValueError, match=r"query 3 feature left_foot_position\.z is not finite"):
        search.search(bad)


def test_unknown_backend_lists_the_known_ones(db):
    with pytest.raises(ValueError, match=r"unknown backend 'kd-tree' \(known: reference, fast-brute"):
        mmvk.Search(db, "kd-tree")


def test_unknown_channel_and_tag(search, queries):
    with pytest.raises(ValueError, match="unknown channel 'head'"):
        search.search(queries, weights={"head": 1.0})
    with pytest.raises(ValueError, match="jog"):
        search.search(queries, require=["jog"])


def test_bad_k_and_option(search, queries, db):
    with pytest.raises(ValueError, match="k"):
        search.search(queries, k=0)
    with pytest.raises(ValueError, match="unknown Search option 'nprobes'"):
        mmvk.Search(db, "clusters-nprobe", nprobes=2)


def test_missing_files(db):
    with pytest.raises(OSError, match="no such file"):
        mmvk.Database.load("/nonexistent.mmdb")
    with pytest.raises(OSError):
        mmvk.Search(db, "clusters", clusters="/nonexistent.mmkc")
