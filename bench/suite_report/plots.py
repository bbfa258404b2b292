"""The suite's plots, as SVG (matplotlib, Agg backend, no display):
  qps_vs_batch.svg   - queries/s against batch size per backend
  recall_vs_time.svg - recall@1 (and @10) against µs/query for the
                       approximate methods, one point per nprobe or K
  us_vs_n.svg        - µs/query against N per backend (log-log)
Each reads on its own: titles, axes with units, legends, log scales.
Families keep one colour in every plot; mmvk's CPU backends are solid
lines, its Vulkan backends dashed, the peers dotted."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

from .cells import DATASETS, method_info, method_order  # noqa: E402

# Reproducible SVG: no timestamp, fixed ids, text kept as text (small files,
# readable diffs).
matplotlib.rcParams.update({"svg.hashsalt": "mmvk-suite", "svg.fonttype": "none", "font.size": 9,
                            "axes.titlesize": 10, "legend.fontsize": 8})
_SVG_METADATA = {"Date": None, "Creator": "mmvk bench/report"}

_COLOURS = {
    "reference": "#7f7f7f", "fast-brute": "#1f77b4", "fast-box": "#17becf", "clusters": "#2ca02c",
    "nprobe": "#98df8a", "vulkan-brute": "#9467bd", "vulkan-clusters": "#8c564b", "vulkan-nprobe": "#c5b0d5",
    "faiss-flat": "#d62728", "faiss-flat-1q": "#ff9896", "faiss-ivf": "#ff7f0e", "pca-kdtree": "#bcbd22",
    "box-scan": "#e377c2",
}
_MARKERS = "osD^v<>ph*X"
_RECALL_TARGET = 0.99
# What the number after an approximate method's name is (the point labels).
_PARAMETER = {"nprobe": "clusters probed", "vulkan-nprobe": "clusters probed", "faiss-ivf": "lists probed",
              "pca-kdtree": "candidates"}


def style(method):
    family, _, owner, _ = method_info(method)
    linestyle = {"mmvk": "-", "mmvk-vulkan": "--"}.get(owner, ":")
    families = list(_COLOURS)
    marker = _MARKERS[(families.index(family) if family in families else len(families)) % len(_MARKERS)]
    return {"color": _COLOURS.get(family, "#000000"), "linestyle": linestyle, "marker": marker}


def representatives(methods, batch=1024):
    """The methods to draw as one line each: every exact method, and per
    approximate family the cheapest setting reaching recall@1 >= 0.99 at
    `batch` (or the family's largest batch), else its most accurate one."""
    chosen, by_family = [], {}
    for method, cells in methods.items():
        family, param, _, exact = method_info(method)
        if exact or param is None:
            chosen.append(method)
            continue
        ok = [c for c in cells if not c.error and c.us_per_query]
        if ok:
            by_family.setdefault(family, []).append((method, ok))
    for family, options in by_family.items():
        have = {c.batch for _, cells in options for c in cells}
        at = batch if batch in have else max(have)
        scored = [(m, c) for m, cells in options for c in cells if c.batch == at]
        good = [(m, c) for m, c in scored if (c.get("recall1") or 0) >= _RECALL_TARGET]
        if good:
            chosen.append(min(good, key=lambda mc: mc[1].us_per_query)[0])
        elif scored:
            chosen.append(max(scored, key=lambda mc: (mc[1].get("recall1") or 0, -mc[1].us_per_query))[0])
    return sorted(chosen, key=method_order)


def _panels(index, schema, stream):
    """The data sets measured for (schema, stream), smallest first."""
    known = [d for d in DATASETS if (d, schema, stream) in index.groups]
    return known + sorted(d for (d, s, st) in index.groups if s == schema and st == stream and d not in known)


def _ticks(ax, values, label):
    """Ticks at the measured values (batch sizes, N), labelled plainly."""
    ax.set_xticks(values, [label(v) for v in values])
    ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())


def _finish(fig, axes, path, title):
    handles, labels = {}, []
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            if label not in handles:
                handles[label] = handle
                labels.append(label)
    labels.sort(key=method_order)
    fig.suptitle(title)
    fig.legend([handles[label] for label in labels], labels, loc="center left", bbox_to_anchor=(1.0, 0.5),
               title="method (solid: mmvk CPU,\ndashed: mmvk Vulkan,\ndotted: peers)", frameon=False)
    fig.tight_layout()
    fig.savefig(path, format="svg", bbox_inches="tight", metadata=_SVG_METADATA)
    plt.close(fig)


def _n_title(index, dataset):
    n = index.n_of(dataset)
    return f"{dataset} (N = {n:,} frames)" if n else dataset


def qps_vs_batch(index, path, schema="default27", stream="transition"):
    datasets = _panels(index, schema, stream)
    # Only the sets measured at three batches or more, where a curve says
    # something (the scale series has two).
    swept = [d for d in datasets
             if len({c.batch for cells in index.groups[(d, schema, stream)].values() for c in cells}) >= 3]
    datasets = swept or datasets
    if not datasets:
        return False
    fig, axes = plt.subplots(1, len(datasets), figsize=(3.6 * len(datasets), 3.6), squeeze=False)
    axes = axes[0]
    for ax, dataset in zip(axes, datasets):
        methods = index.groups[(dataset, schema, stream)]
        for method in representatives(methods):
            cells = sorted((c for c in methods[method] if not c.error and c.queries_per_s), key=lambda c: c.batch)
            if cells:
                ax.plot([c.batch for c in cells], [c.queries_per_s for c in cells], label=method, markersize=4,
                        **style(method))
        ax.set_xscale("log", base=2)
        ax.set_yscale("log")
        _ticks(ax, sorted({c.batch for cells in methods.values() for c in cells}), str)
        ax.set_xlabel("batch size B (queries per call)")
        ax.set_ylabel("queries per second (wall clock)")
        ax.set_title(_n_title(index, dataset))
        ax.grid(True, which="major", alpha=0.3)
    _finish(fig, axes, path, f"Throughput against batch size — {stream} stream, {schema} schema (higher is better)\n"
            "approximate: cheapest setting with recall@1 ≥ 0.99 (else most accurate)")
    return True


def recall_vs_time(index, path, schema="default27", stream="transition", batch=1024):
    datasets = [d for d in _panels(index, schema, stream)
                if any(not method_info(m)[3] and any(c.batch == batch for c in cells)
                       for m, cells in index.groups[(d, schema, stream)].items())]
    if not datasets:
        return False
    has_r10 = any(c.get("recall10") is not None for c in index.cells.values() if not method_info(c.method)[3])
    rows = 2 if has_r10 else 1
    fig, axes = plt.subplots(rows, len(datasets), figsize=(3.8 * len(datasets), 3.4 * rows), squeeze=False)
    for column, dataset in enumerate(datasets):
        methods = index.groups[(dataset, schema, stream)]
        families = {}
        for method, cells in methods.items():
            for c in cells:
                if c.batch == batch and not c.error and c.us_per_query:
                    families.setdefault(method_info(method)[0], []).append((method, c))
        for row, counter in enumerate(["recall1", "recall10"][:rows]):
            ax = axes[row][column]
            for family, points in sorted(families.items(), key=lambda f: method_order(f[1][0][0])):
                points = [(m, c) for m, c in points if c.get(counter) is not None]
                if not points:
                    continue
                exact = method_info(points[0][0])[3]
                points.sort(key=lambda mc: method_info(mc[0])[1] or 0)
                xs = [c.us_per_query for _, c in points]
                ys = [c.get(counter) for _, c in points]
                st = style(points[0][0])
                label = family if exact else f"{family}<{_PARAMETER.get(family, 'setting')}>"
                ax.plot(xs, ys, label=label, markersize=6 if exact else 4,
                        linestyle="none" if exact else st["linestyle"], marker=st["marker"], color=st["color"])
                if not exact:
                    for (m, c), x, y in zip(points, xs, ys):
                        ax.annotate(str(method_info(m)[1]), (x, y), textcoords="offset points", xytext=(3, -9),
                                    fontsize=7, color=st["color"])
            ax.set_xscale("log")
            ax.set_xlabel("µs per query (wall clock, lower is better)")
            ax.set_ylabel("recall@1 against the exact answer" if counter == "recall1" else "recall@10")
            ax.axhline(_RECALL_TARGET, color="#bbbbbb", linewidth=0.8, linestyle="-.")
            ax.set_title(_n_title(index, dataset))
            ax.grid(True, which="major", alpha=0.3)
    _finish(fig, [a for r in axes for a in r], path,
            f"Recall against time — {stream} stream, {schema} schema, B = {batch} (up and left is better)\n"
            "point labels: the setting (clusters or lists probed, KD-tree candidates); dash-dot line: recall 0.99")
    return True


def us_vs_n(index, path, schema="default27", stream="transition", batches=(1, 1024)):
    datasets = _panels(index, schema, stream)
    ns = {d: index.n_of(d) for d in datasets}
    datasets = [d for d in datasets if ns[d]]
    if len(datasets) < 2:
        return False
    batches = [b for b in batches if any(c.batch == b for d in datasets for cs in index.groups[(d, schema, stream)].values()
                                         for c in cs)]
    if not batches:
        return False
    largest = datasets[-1]
    fig, axes = plt.subplots(1, len(batches), figsize=(4.6 * len(batches), 3.8), squeeze=False)
    axes = axes[0]
    for ax, batch in zip(axes, batches):
        # The same settings at every N: those chosen on the largest set.
        chosen = set(representatives(index.groups[(largest, schema, stream)], batch))
        for d in datasets:
            chosen |= {m for m in index.groups[(d, schema, stream)] if method_info(m)[3]}
        chosen = sorted(chosen, key=method_order)
        for method in chosen:
            points = []
            for d in datasets:
                for c in index.groups[(d, schema, stream)].get(method, []):
                    if c.batch == batch and not c.error and c.us_per_query:
                        points.append((ns[d], c.us_per_query))
            if points:
                points.sort()
                ax.plot([p[0] for p in points], [p[1] for p in points], label=method, markersize=4, **style(method))
        ax.set_xscale("log")
        ax.set_yscale("log")
        lo, hi = ns[datasets[0]], ns[datasets[-1]]
        # A guide with the slope of a linear scan, near the bottom.
        ymin, _ = ax.get_ylim()
        ax.plot([lo, hi], [ymin * 2, ymin * 2 * hi / lo], color="#444444", linewidth=0.8, linestyle="-.",
                label="∝ N (linear scan)")
        _ticks(ax, [ns[d] for d in datasets], lambda n: f"{n / 1000:.0f}k")
        ax.set_xlabel("database size N (frames)")
        ax.set_ylabel("µs per query (wall clock)")
        ax.set_title(f"B = {batch}")
        ax.grid(True, which="both", alpha=0.3)
    _finish(fig, axes, path, f"Cost against database size — {stream} stream, {schema} schema "
            "(flatter than the ∝ N line = sublinear)")
    return True
