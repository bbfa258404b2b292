#!/usr/bin/env python3
"""The Python module's overhead: Search.search against the same backend call in C++.

    PYTHONPATH=build/python python3 bench/python_overhead.py [--db build/bench-data/volume.mmdb]
        [--backend clusters] [--threads 0] [--samples 60]

Both sides search the same queries on the same mmvk.Search (one backend):
`search.search(q, k=1)` from a Python loop (argument checks, the result
arrays, the GIL released and taken back) against `search._native_seconds`,
the backend's search() called from a C++ loop. At each batch size the two
alternate sample by sample (a sample: one call at B = 1024, a run of calls
lasting about 2 ms at B = 1) and the medians are compared, so load that
comes and goes during the run falls on both alike. The database is the Bandai volume set
the C++ benchmarks build and cache (bench/bench_data.hpp): any
`build/bench/mmvk_bench --benchmark_filter='^real/volume/transition/clusters/B:1/'`
run makes build/bench-data/volume.mmdb.
"""
import argparse
import os
import pathlib
import platform
import statistics
import time

import numpy as np

import mmvk

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--db", type=pathlib.Path, default=pathlib.Path("build/bench-data/volume.mmdb"))
parser.add_argument("--backend", default="clusters")
parser.add_argument("--threads", type=int, default=0, help="CPU backend threads (0 = all cores)")
parser.add_argument("--samples", type=int, default=60, help="alternating samples per batch size and side")
args = parser.parse_args()

db = mmvk.Database.load(args.db)
search = mmvk.Search(db, args.backend, threads=args.threads)
rng = np.random.default_rng(1)
# Queries near database rows (a "transition" stream: a character between frames).
rows = rng.integers(0, db.frame_count, size=1024)
queries = np.ascontiguousarray(db.features[rows] + rng.normal(0, 0.3, (1024, db.dims)).astype(np.float32))

print(f"# {db} on {search} (python {platform.python_version()}, numpy {np.__version__}, {os.cpu_count()} CPUs)")
print("| B | calls per sample | C++ ms/call | Python ms/call | overhead | overhead per call |")
print("|---:|---:|---:|---:|---:|---:|")
for batch in (1024, 1):
    q = queries[:batch]
    search.search(q)  # warm up (caches, pages)
    once = search._native_seconds(q, 1, 3)
    calls = max(1, int(2e-3 / once))
    native, python = [], []
    for _ in range(args.samples):
        native.append(search._native_seconds(q, 1, calls))
        start = time.perf_counter()
        for _ in range(calls):
            search.search(q)
        python.append((time.perf_counter() - start) / calls)
    n, p = statistics.median(native), statistics.median(python)
    print(f"| {batch} | {calls} | {n * 1e3:.4f} | {p * 1e3:.4f} | {100 * (p / n - 1):+.1f}% | {(p - n) * 1e6:+.1f} µs |")
