"""Google Benchmark JSON -> the suite's cells.

A cell is one benchmark of the suite matrix, named
``suite/<dataset>/<schema>/<stream>/<method>/B:<batch>`` by mmvk_suite, with
the user counters of the suite's contract (us_per_query, queries_per_s,
rows_fraction, recall1, recall10, db_bytes, index_bytes, device_bytes,
build_s, kernel_us_per_query, N, dims). Cells of the older mmvk_bench
(``real/...`` and ``vclusters/...``) are read too, mapped onto the same
fields, so the report also works on a build without the suite executable.
Calibration benchmarks (``calibration/...``) are kept apart for the machine
context.
"""

from __future__ import annotations

import json
import re
import statistics
from dataclasses import dataclass, field
from pathlib import Path

DATASETS = ["locomotion", "volume104k", "volume", "volume-mirrored"]
SCHEMAS = ["default27", "wide60"]
STREAMS = ["continue", "transition", "uniform"]
BATCHES = [1, 64, 1024, 8192]

# Frame counts of the data sets (bench/bench_data.hpp), for old cells that
# carry no N counter.
KNOWN_N = {"locomotion": 21791, "volume": 416845, "volume-mirrored": 833690}

# Methods in report order: (pattern, family, owner, exact). A family groups
# the settings of one approximate method (nprobe 1, 4, ...); `owner` is
# "mmvk" (CPU), "mmvk-vulkan" or "peer".
METHODS = [
    (r"reference", "reference", "mmvk", True),
    (r"fast-brute", "fast-brute", "mmvk", True),
    (r"fast-box", "fast-box", "mmvk", True),
    (r"clusters", "clusters", "mmvk", True),
    (r"nprobe\d+", "nprobe", "mmvk", False),
    (r"vulkan-brute", "vulkan-brute", "mmvk-vulkan", True),
    (r"vulkan-clusters", "vulkan-clusters", "mmvk-vulkan", True),
    (r"vulkan-nprobe\d+", "vulkan-nprobe", "mmvk-vulkan", False),
    (r"faiss-flat", "faiss-flat", "peer", True),
    (r"faiss-flat-1q", "faiss-flat-1q", "peer", True),
    (r"faiss-ivf\d+", "faiss-ivf", "peer", False),
    (r"pca-kdtree\d+", "pca-kdtree", "peer", False),
    (r"box-scan", "box-scan", "peer", True),
]

# What a reader is told when a whole family is absent from the input.
PEERS = {
    "FAISS": ("faiss-flat", "faiss-flat-1q", "faiss-ivf"),
    "PCA + KD-tree (nanoflann)": ("pca-kdtree",),
    "two-level box scan": ("box-scan",),
}
VULKAN_FAMILIES = ("vulkan-brute", "vulkan-clusters", "vulkan-nprobe")

_UNIT_TO_US = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}


def method_info(method: str):
    """(family, parameter or None, owner, exact) of a method name; unknown
    methods form their own family, owner "other", and count as exact only
    when their recall says so."""
    for pattern, family, owner, exact in METHODS:
        if re.fullmatch(pattern, method):
            digits = re.search(r"\d+$", method) if not exact else None
            return family, int(digits.group()) if digits else None, owner, exact
    return method, None, "other", False


def method_order(method: str):
    family, param, _, _ = method_info(method)
    for index, (_, fam, _, _) in enumerate(METHODS):
        if fam == family:
            return (index, param or 0, method)
    return (len(METHODS), 0, method)


@dataclass
class Cell:
    dataset: str
    schema: str
    stream: str
    method: str
    batch: int
    counters: dict = field(default_factory=dict)
    error: str | None = None
    source: str = "suite"  # "suite", or the old benchmark family it was mapped from

    @property
    def key(self):
        return (self.dataset, self.schema, self.stream, self.method, self.batch)

    def get(self, name):
        """A counter as a float; None when absent or NaN (not measured)."""
        value = self.counters.get(name)
        if value is None or value != value:
            return None
        return float(value)

    @property
    def us_per_query(self):
        return self.get("us_per_query")

    @property
    def queries_per_s(self):
        qps = self.get("queries_per_s")
        if qps is None and self.us_per_query:
            qps = 1e6 / self.us_per_query
        return qps


@dataclass
class Calibration:
    name: str
    counters: dict
    label: str = ""
    error: str | None = None


@dataclass
class Input:
    cells: dict  # Cell.key -> Cell
    calibrations: dict  # name -> Calibration
    contexts: list  # Google Benchmark "context" objects, one per file
    files: list


_SUITE = re.compile(r"suite/(?P<dataset>[^/]+)/(?P<schema>[^/]+)/(?P<stream>[^/]+)/(?P<method>[^/]+)/B:(?P<batch>\d+)")
_REAL = re.compile(r"real/(?P<dataset>[^/]+)/(?P<stream>[^/]+)/(?P<method>[^/]+)/B:(?P<batch>\d+)")
_VCLUSTERS = re.compile(r"vclusters/(?P<dataset>[^/]+)/(?P<stream>[^/]+)/(?P<method>[^/]+)/B:(?P<batch>\d+)")


def _time_us(run):
    return float(run["real_time"]) * _UNIT_TO_US.get(run.get("time_unit", "ns"), 1e-3)


def _merge_runs(runs):
    """One run per benchmark: the median aggregate when repetitions were
    aggregated, else the per-key median of the repetitions."""
    medians = [r for r in runs if r.get("run_type") == "aggregate" and r.get("aggregate_name") == "median"]
    if medians:
        return medians[0]
    iterations = [r for r in runs if r.get("run_type", "iteration") == "iteration"]
    if not iterations:
        return None
    if len(iterations) == 1:
        return iterations[0]
    merged = dict(iterations[0])
    for key, value in iterations[0].items():
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            values = [r[key] for r in iterations if isinstance(r.get(key), (int, float))]
            merged[key] = statistics.median(values)
    return merged


def _suite_cell(match, run):
    cell = Cell(match["dataset"], match["schema"], match["stream"], match["method"], int(match["batch"]))
    cell.counters = {k: v for k, v in run.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    if "us_per_query" not in cell.counters and "real_time" in run and cell.batch > 0:
        cell.counters["us_per_query"] = _time_us(run) / cell.batch
    return cell


def _legacy_cell(match, run, source):
    """An mmvk_bench cell in the suite's terms: default schema, nprobe
    methods named as in the suite, counters renamed."""
    method = re.sub(r"^clusters-nprobe", "nprobe", match["method"])
    cell = Cell(match["dataset"], "default27", match["stream"], method, int(match["batch"]), source=source)
    c = cell.counters
    c["us_per_query"] = _time_us(run) / cell.batch
    if "queries/s" in run:
        c["queries_per_s"] = float(run["queries/s"])
    for old, new in (("rows_fraction", "rows_fraction"), ("rows", "rows_fraction"), ("recall@1", "recall1"),
                     ("frames", "N")):
        if old in run:
            c[new] = float(run[old])
    if "kernel_ms" in run:
        c["kernel_us_per_query"] = float(run["kernel_ms"]) * 1e3 / cell.batch
    c.setdefault("N", KNOWN_N.get(cell.dataset))
    if c["N"] is None:
        del c["N"]
    c.setdefault("dims", 27)
    return cell


def _base_name(run):
    # run_name drops the aggregate suffix; "/real_time", "/threads:2" and the
    # like stay in it and are matched around.
    return run.get("run_name") or run["name"]


def load(paths) -> Input:
    data = Input(cells={}, calibrations={}, contexts=[], files=[str(p) for p in paths])
    for path in paths:
        document = json.loads(Path(path).read_text())
        data.contexts.append(document.get("context", {}))
        grouped = {}
        for run in document.get("benchmarks", []):
            grouped.setdefault(_base_name(run), []).append(run)
        for name, runs in grouped.items():
            errors = [r for r in runs if r.get("error_occurred")]
            run = _merge_runs(runs) if not errors else errors[0]
            if run is None:
                continue
            error = run.get("error_message", "skipped") if errors else None
            if name.startswith("calibration/") or name.startswith("machine/"):
                data.calibrations[name] = Calibration(name, run, run.get("label", ""), error)
                continue
            cell = None
            if m := _SUITE.match(name):
                cell = _suite_cell(m, run)
            elif m := _REAL.match(name):
                cell = _legacy_cell(m, run, "real")
            elif m := _VCLUSTERS.match(name):
                cell = _legacy_cell(m, run, "vclusters")
            if cell is None:
                continue
            cell.error = error
            # A suite cell wins over an old cell of the same key; later
            # files win over earlier ones (a re-run of a slice).
            existing = data.cells.get(cell.key)
            if existing is None or existing.source != "suite" or cell.source == "suite":
                data.cells[cell.key] = cell
    return data

