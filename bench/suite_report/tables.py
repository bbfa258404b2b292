"""The suite's section of bench/RESULTS.md, as Markdown: the run and machine
context, the fraction-of-limit headline, one table per data set, schema
and stream, and µs/query against N."""

from __future__ import annotations

import math

from .cells import BATCHES, DATASETS, PEERS, SCHEMAS, STREAMS, VULKAN_FAMILIES, method_info, method_order

DASH = "–"


def sig(value, digits=3):
    """`value` to `digits` significant digits, plainly (no exponent)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return DASH
    if value == 0:
        return "0"
    magnitude = int(math.floor(math.log10(abs(value))))
    decimals = max(digits - 1 - magnitude, 0)
    return f"{value:,.{decimals}f}"


def rate(value):
    """Queries/s with a k or M suffix."""
    if value is None:
        return DASH
    for factor, suffix in ((1e6, "M"), (1e3, "k")):
        if value >= factor:
            return sig(value / factor) + suffix
    return sig(value)


def mib(value):
    return DASH if value is None else sig(value / 2**20)


def percent(value):
    return DASH if value is None else sig(100.0 * value) + "%"


def rank(value, order):
    return order.index(value) if value in order else len(order)


def _largest_batch(cells):
    ok = [c for c in cells if not c.error]
    return max(ok, key=lambda c: c.batch) if ok else None


class Index:
    """Cells looked up by (dataset, schema, stream) and method."""

    def __init__(self, cells):
        self.cells = cells
        self.groups = {}
        for cell in cells.values():
            self.groups.setdefault((cell.dataset, cell.schema, cell.stream), {}).setdefault(cell.method, []).append(cell)

    def group_keys(self):
        return sorted(self.groups, key=lambda k: (rank(k[0], DATASETS), rank(k[1], SCHEMAS), rank(k[2], STREAMS), k))

    def families(self):
        return {method_info(c.method)[0] for c in self.cells.values()}

    def n_of(self, dataset, schema="default27"):
        for cell in self.cells.values():
            if cell.dataset == dataset and cell.get("N"):
                return int(cell.get("N"))
        return None


def seconds(value):
    """A build time: small ones as a bound rather than a string of zeros."""
    if not value:
        return DASH
    return "< 0.001" if value < 1e-3 else sig(value)


def speedup(methods, method, baseline="fast-brute", prefer=1024):
    """(ratio, batch): baseline's µs/query over method's, at B = `prefer`
    when both have it, else at the largest batch both have."""
    mine = {c.batch: c.us_per_query for c in methods.get(method, []) if not c.error and c.us_per_query}
    base = {c.batch: c.us_per_query for c in methods.get(baseline, []) if not c.error and c.us_per_query}
    common = set(mine) & set(base)
    if not common:
        return None, None
    batch = prefer if prefer in common else max(common)
    return base[batch] / mine[batch], batch


def group_table(methods):
    """One table: a row per method, µs/query per batch, its speed against
    fast-brute, the rest at the method's largest batch."""
    batches = sorted({c.batch for cells in methods.values() for c in cells})
    batches = [b for b in BATCHES if b in batches] + [b for b in batches if b not in BATCHES]
    header = (["method"] + [f"µs/q B={b}" for b in batches] +
              ["x fast-brute", "best q/s", "rows eval.", "recall@1", "recall@10", "host MiB (db + index)", "device MiB", "build s",
               "kernel µs/q"])
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    notes = []
    for method in sorted(methods, key=method_order):
        cells = {c.batch: c for c in methods[method]}
        row = [f"`{method}`"]
        for b in batches:
            cell = cells.get(b)
            if cell is None:
                row.append(DASH)
            elif cell.error:
                row.append("skipped")
                notes.append(f"`{method}` B={b}: {cell.error}")
            else:
                row.append(sig(cell.us_per_query))
        ratio, at = speedup(methods, method)
        row.append(DASH if ratio is None else f"{ratio:.2f}x" + ("" if at == 1024 else f" (B={at})"))
        best = max((c for c in cells.values() if not c.error and c.queries_per_s), key=lambda c: c.queries_per_s,
                   default=None)
        last = _largest_batch(cells.values())
        row.append(f"{rate(best.queries_per_s)} (B={best.batch})" if best else DASH)
        if last is None:
            row += [DASH] * 7
        else:
            host = None
            if last.get("db_bytes") is not None or last.get("index_bytes") is not None:
                host = (last.get("db_bytes") or 0) + (last.get("index_bytes") or 0)
            row += [percent(last.get("rows_fraction")), sig(last.get("recall1"), 4), sig(last.get("recall10"), 4),
                    mib(host), mib(last.get("device_bytes")) if last.get("device_bytes") else DASH,
                    seconds(last.get("build_s")),
                    sig(last.get("kernel_us_per_query")) if last.get("kernel_us_per_query") else DASH]
        lines.append("| " + " | ".join(row) + " |")
    return lines, notes


def missing_note(index):
    """What is absent from the input, said plainly (a peer not built, no Vulkan)."""
    families = index.families()
    lines = []
    for peer, peer_families in PEERS.items():
        if not families.intersection(peer_families):
            lines.append(f"- {peer}: no cells in this run (the peer was not built: its package was missing at "
                         "configure time, or the run's filter left it out).")
    if not families.intersection(VULKAN_FAMILIES):
        lines.append("- mmvk Vulkan backends: no cells in this run (built without Vulkan, no device, or filtered out).")
    return lines


def flops_per_row_dim(method):
    """Arithmetic per evaluated row x dim: mmvk's exact cost is subtract,
    multiply, add (3 flops, kept apart for bit parity with the reference);
    FAISS computes |x|^2 - 2x.y + |y|^2 as a matrix product (one FMA, 2 flops)."""
    return 2 if method.startswith("faiss") else 3


def headline(index, machine, dataset, schema, stream):
    """Throughput of the brute-force methods as a fraction of the measured
    FMA ceiling (all cores), and at B=1 the read rate against the streaming
    bandwidth (at larger batches a row is read once for many queries)."""
    methods = index.groups.get((dataset, schema, stream), {})
    ceiling = machine.fma_ceiling
    stream_limit = machine.stream_ceiling
    lines = ["| method | B | G row·dims/s | GFLOP/s | of the FMA ceiling | GB/s read (B=1) | of the read bandwidth |",
             "|---|---|---|---|---|---|---|"]
    rows = 0
    for method in sorted(methods, key=method_order):
        family, _, owner, exact = method_info(method)
        if family not in ("reference", "fast-brute", "fast-box", "clusters", "vulkan-brute", "faiss-flat",
                          "faiss-flat-1q", "box-scan"):
            continue
        for cell in sorted(methods[method], key=lambda c: c.batch):
            if cell.error or cell.batch not in (1, 1024) or not cell.queries_per_s:
                continue
            n, dims, fraction = cell.get("N"), cell.get("dims"), cell.get("rows_fraction")
            if not (n and dims and fraction is not None):
                continue
            row_dims = cell.queries_per_s * fraction * n * dims
            gflops = row_dims * flops_per_row_dim(method) / 1e9
            read = row_dims * 4 / 1e9 if cell.batch == 1 else None
            lines.append(f"| `{method}` | {cell.batch} | {sig(row_dims / 1e9)} | {sig(gflops)} | "
                         f"{percent(gflops / ceiling) if ceiling else DASH} | {sig(read) if read else DASH} | "
                         f"{percent(read / stream_limit) if read and stream_limit else DASH} |")
            rows += 1
    return lines if rows else []


def scale_table(index, schema="default27", stream="transition", batches=(1, 1024)):
    """µs/query against N per method, and the growth exponent (slope of
    log µs against log N between the smallest and largest N measured)."""
    datasets = [d for d in DATASETS if any(k[0] == d and k[1] == schema and k[2] == stream for k in index.groups)]
    if len(datasets) < 2:
        return []
    ns = {d: index.n_of(d) for d in datasets}
    lines = []
    for batch in batches:
        methods = {}
        for d in datasets:
            for method, cells in index.groups.get((d, schema, stream), {}).items():
                for c in cells:
                    if c.batch == batch and not c.error and c.us_per_query:
                        methods.setdefault(method, {})[d] = c.us_per_query
        if not methods:
            continue
        header = ["method"] + [f"{d} (N = {ns[d]:,})" if ns[d] else d for d in datasets] + ["growth exponent"]
        lines += [f"B = {batch}, {stream} stream, {schema} schema (µs per query; exponent 1 = linear in N):", "",
                  "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
        for method in sorted(methods, key=method_order):
            values = methods[method]
            row = [f"`{method}`"] + [sig(values.get(d)) for d in datasets]
            measured = [d for d in datasets if d in values and ns[d]]
            if len(measured) >= 2 and ns[measured[-1]] != ns[measured[0]]:
                lo, hi = measured[0], measured[-1]
                slope = math.log(values[hi] / values[lo]) / math.log(ns[hi] / ns[lo])
                row.append(f"{slope:.2f}")
            else:
                row.append(DASH)
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
    return lines


def faiss_agreement(index):
    """FAISS flat against the reference: where the top-1 differs, and how
    many of those are float near-ties (a `near_ties` counter from the suite)."""
    lines = []
    for key in index.group_keys():
        for method in ("faiss-flat", "faiss-flat-1q"):
            # The largest batch: the most queries behind the figure.
            cell = _largest_batch(c for c in index.groups[key].get(method, []) if c.get("recall1") is not None)
            if cell is not None:
                # mmvk_suite measures recall on the first 1024 queries of the
                # stream (kRecallQueries); mmvk_bench's cells on the batch.
                queries = cell.get("recall_queries") or (1024 if cell.source == "suite" else cell.batch)
                differs = round((1 - cell.get("recall1")) * queries)
                ties = cell.get("near_ties")
                lines.append(f"| {key[0]} | {key[1]} | {key[2]} | `{method}` | {sig(cell.get('recall1'), 4)}"
                             f" | {differs} | {DASH if ties is None else int(ties)} |")
    if not lines:
        return []
    return ["| data set | schema | stream | method | recall@1 | top-1 differs (of 1024 queries) | of which near-ties |",
            "|---|---|---|---|---|---|---|"] + lines


def head_to_head(index, dataset="volume", schema="default27", stream="transition", batch=1024, target=0.99):
    """The comparisons the suite is for, at one cell of the matrix: every
    exact method's µs/query against mmvk's exact cluster search, and per
    approximate family the cheapest setting reaching recall@1 >= target."""
    methods = index.groups.get((dataset, schema, stream), {})
    at = {m: c for m, cells in methods.items() for c in cells if c.batch == batch and not c.error and c.us_per_query}
    if "clusters" not in at:
        return []
    base = at["clusters"].us_per_query
    lines = ["| exact method | µs/query | time / mmvk `clusters` |", "|---|---|---|"]
    for method in sorted(at, key=method_order):
        family, _, _, exact = method_info(method)
        if exact:
            lines.append(f"| `{method}` | {sig(at[method].us_per_query)} | {at[method].us_per_query / base:.2f} |")
    lines += ["", f"| approximate family | cheapest setting with recall@1 ≥ {target} | µs/query | recall@1 | "
              "time / mmvk `clusters` |", "|---|---|---|---|---|"]
    families = {}
    for method, cell in at.items():
        family, param, _, exact = method_info(method)
        if not exact and param is not None:
            families.setdefault(family, []).append((method, cell))
    for family in sorted(families, key=lambda f: method_order(families[f][0][0])):
        options = families[family]
        good = [(m, c) for m, c in options if (c.get("recall1") or 0) >= target]
        if good:
            method, cell = min(good, key=lambda mc: mc[1].us_per_query)
            lines.append(f"| {family} | `{method}` | {sig(cell.us_per_query)} | {sig(cell.get('recall1'), 4)} | "
                         f"{cell.us_per_query / base:.2f} |")
        else:
            method, cell = max(options, key=lambda mc: mc[1].get("recall1") or 0)
            lines.append(f"| {family} | none (best: `{method}`) | {sig(cell.us_per_query)} | "
                         f"{sig(cell.get('recall1'), 4)} | {cell.us_per_query / base:.2f} |")
    return lines
