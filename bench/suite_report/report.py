"""bench/report: Google Benchmark JSON of the suite -> the suite section of
bench/RESULTS.md (between the markers below; the rest of the file is left
as it is) and the SVG plots in bench/plots/."""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

from . import cells as cells_mod
from . import machine as machine_mod
from . import tables

BEGIN = "<!-- suite:begin -->"
END = "<!-- suite:end -->"
PLOTS = [("qps_vs_batch.svg", "queries/s against batch size per backend"),
         ("recall_vs_time.svg", "recall against µs/query for the approximate methods (one point per nprobe or K)"),
         ("us_vs_n.svg", "µs/query against N per backend, log-log")]

STREAMS_DOC = (
    "Streams (bench/query_streams.hpp, seed 42 unless the cell says otherwise): **continue** = a random frame's "
    "features plus small Gaussian noise; **transition** = the pose channels of one random frame with the "
    "trajectory channels of another; **uniform** = every dimension uniform within the database's range.")
CONDITIONS_DOC = (
    "Every method answers plain nearest neighbour (k = 1 for the time; recall@10 from a k = 10 pass): queries "
    "carry no constraints and no biases, and the database is built with every frame a candidate, because the "
    "peers (FAISS, the KD-tree, the box scan) cannot apply mmvk's per-query rules. µs/query and queries/s are "
    "wall clock over the whole batch (all cores for the multi-threaded methods); recall is against the "
    "reference's exact answer; `rows eval.` is the fraction of (query, row) pairs whose full cost was computed; "
    "memory, recall, rows and kernel time are given at each method's largest batch.")


def _machine_lines(machine, data):
    m = machine
    lines = []
    width = f"{m.vector_bits}-bit vectors" + (" (AVX-512F)" if m.vector_bits == 512 else "") if m.vector_bits else "unknown vector width"
    lines.append(f"- CPU: {m.cpu_model}, {m.cores} cores as seen by the process, {width}.")
    if m.fma_gflops_per_core:
        parts = [f"{kind.upper()} {tables.sig(value)} GFLOP/s per core ({tables.sig(m.fma_gflops_wall[kind])} per wall second)"
                 for kind, value in sorted(m.fma_gflops_per_core.items())]
        lines.append(f"- FMA ceiling (`calibration/fma_peak`, one thread, 10 independent FMA chains): "
                     f"{'; '.join(parts)}; the machine: **{tables.sig(m.fma_ceiling)} GFLOP/s** "
                     f"({m.cores} cores at the widest).")
    else:
        lines.append("- FMA ceiling: not measured in this run (no `calibration/fma_peak` cells).")
    if m.stream_gbs:
        parts = [f"{t} thread{'s' if t > 1 else ''} {tables.sig(v)} GB/s ({tables.sig(m.stream_gbs_wall[t])} per wall second)"
                 for t, v in sorted(m.stream_gbs.items())]
        lines.append(f"- Streaming read (`calibration/stream_read`, 512 MiB summed with AVX2 loads): {'; '.join(parts)}.")
    else:
        lines.append("- Streaming read bandwidth: not measured in this run.")
    lines.append("  Ceilings are per CPU-second (the rate while the thread runs), so that other jobs on this shared "
                 "machine do not lower the limit; search cells are wall clock.")
    if m.vulkan:
        lines.append(f"- Vulkan: {m.vulkan}.")
    else:
        lines.append(f"- Vulkan: none in this run ({m.vulkan_error or 'no calibration/vulkan_device cell'}).")
    policies = sorted({c["omp_wait_policy"] for c in data.contexts if c.get("omp_wait_policy")})
    if policies:
        lines.append(f"- OpenMP (FAISS, OpenBLAS): `OMP_WAIT_POLICY={', '.join(policies)}`.")
    blas = sorted({c["blas"] for c in data.contexts if c.get("blas")})
    if blas:
        lines.append(f"- BLAS under FAISS: {'; '.join(blas)} (FAISS's threads and BLAS block: each FAISS cell's "
                     "label in the JSON, chosen by a sweep; bench/peers/README.md).")
    load = ", ".join(f"{x:.1f}" for x in m.load_avg) if m.load_avg else "?"
    lines.append(f"- Load average at the start of the first file: {load}; Google Benchmark's date: {m.date or '?'}.")
    return lines


def _run_lines(machine, data, argv):
    run = machine.run
    lines = []
    if run.get("commands"):
        lines.append("Commands (`bench/run_suite " + run.get("preset_args", "") + "`"
                     + (f", git {run['git']}" if run.get("git") else "") + "):")
        lines += ["", "```"] + run["commands"] + ["```", ""]
    if run.get("started"):
        duration = run.get("duration_s")
        lines.append(f"Run started {run['started']}" + (f", took {duration / 60:.1f} min" if duration else "") + ".")
        if run.get("skipped"):
            lines.append("")
            lines.append("Left out of this preset, and why:")
            lines += [f"- {s}" for s in run["skipped"]]
        lines.append("")
    shown = [os.path.relpath(a) if os.path.isabs(a) else a for a in argv]
    lines.append("Report: `" + " ".join(["bench/report"] + shown) + "`.")
    return lines


def section(data, machine, argv, plots_rel, plots_made):
    index = tables.Index(data.cells)
    out = [BEGIN, "", "_Generated by `bench/report`; edit the script, not this part._", ""]
    out += _run_lines(machine, data, argv) + [""]
    out += ["**Machine**", ""] + _machine_lines(machine, data) + [""]
    out += [STREAMS_DOC, "", CONDITIONS_DOC, ""]
    missing = tables.missing_note(index)
    if missing:
        out += ["**Not in this run**", ""] + missing + [""]
    if not data.cells:
        out += ["No suite cells in the input.", "", END]
        return "\n".join(out) + "\n"
    made = [(name, what) for name, what in PLOTS if name in plots_made]
    if made:
        out += ["**Plots**", ""]
        out += [f"- [{what}]({plots_rel}/{name})" for name, what in made]
        out += [""] + [f"![{what}]({plots_rel}/{name})" for name, what in made] + [""]
    duel = tables.head_to_head(index)
    if duel:
        out += ["### Head to head (volume, default27, transition, B = 1024)", "",
                "Time per query against mmvk's exact cluster search (below 1: faster than it). Exact methods all "
                "return the reference's answers (FAISS flat up to float near-ties); approximate ones at their "
                "cheapest setting that finds the exact top-1 for at least 99% of the queries.", ""] + duel + [""]
    head = tables.headline(index, machine, "volume", "default27", "transition")
    if head:
        out += ["### Against the machine's limit (volume, default27, transition)", "",
                "Brute-force and pruned exact methods as work done per second: evaluated rows x dims, the flops "
                "that takes (3 per row·dim for mmvk's exact subtract-multiply-add, 2 for FAISS's matrix-product "
                "form), and at B = 1 the bytes of rows read; against the measured FMA ceiling of all cores and "
                "the streaming read bandwidth.", ""] + head + [""]
    scale = tables.scale_table(index)
    if scale:
        out += ["### µs/query against N", ""] + scale
    agreement = tables.faiss_agreement(index)
    if agreement:
        out += ["### FAISS flat against the reference", "",
                "Where FAISS's exact flat index returns another top-1 frame than the reference, and how many of "
                "those are float near-ties (the two costs within rounding of each other: FAISS computes "
                "|x|² − 2x·y + |y|², whose rounding differs from the reference's sum of squared differences).",
                ""] + agreement + [""]
    out += ["### Tables", ""]
    notes = []
    for key in index.group_keys():
        dataset, schema, stream = key
        n = index.n_of(dataset)
        title = f"{dataset}" + (f" (N = {n:,})" if n else "") + f", {schema}, {stream}"
        lines, group_notes = tables.group_table(index.groups[key])
        out += [f"#### {title}", ""] + lines + [""]
        notes += [f"{title}: {note}" for note in group_notes]
    if notes:
        out += ["Skipped cells:", ""] + [f"- {n}" for n in notes] + [""]
    out.append(END)
    return "\n".join(out) + "\n"


def splice(existing: str, generated: str) -> str:
    """`existing` with the text between the markers replaced by `generated`;
    appended (after a blank line) when the markers are not there yet."""
    start, end = existing.find(BEGIN), existing.find(END)
    if start != -1 and end > start:
        return existing[:start] + generated.rstrip("\n") + existing[end + len(END):]
    return existing.rstrip("\n") + "\n\n" + generated


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = argparse.ArgumentParser(prog="bench/report", description=__doc__)
    parser.add_argument("json", nargs="+", type=Path, help="Google Benchmark JSON files (--benchmark_out)")
    parser.add_argument("--results", type=Path, default=Path(__file__).resolve().parents[1] / "RESULTS.md",
                        help="the Markdown file to update between the suite markers (default bench/RESULTS.md)")
    parser.add_argument("--plots", type=Path, default=None, help="folder for the SVG plots (default: plots/ beside --results)")
    parser.add_argument("--run-info", type=Path, default=None,
                        help="run.json written by bench/run_suite (default: run.json beside the first input)")
    parser.add_argument("--no-plots", action="store_true", help="tables only")
    args = parser.parse_args(argv)

    missing = [str(p) for p in args.json if not p.exists()]
    if missing:
        parser.error("no such file: " + ", ".join(missing))
    data = cells_mod.load(args.json)
    run_info = args.run_info or args.json[0].parent / "run.json"
    machine = machine_mod.build(data, run_info)
    plots_dir = args.plots or args.results.parent / "plots"
    made = []
    if not args.no_plots and data.cells:
        from . import plots  # matplotlib only when plotting
        plots_dir.mkdir(parents=True, exist_ok=True)
        index = tables.Index(data.cells)
        for name, make in (("qps_vs_batch.svg", plots.qps_vs_batch), ("recall_vs_time.svg", plots.recall_vs_time),
                           ("us_vs_n.svg", plots.us_vs_n)):
            if make(index, plots_dir / name):
                made.append(name)
            else:
                # A stale plot from an earlier run would contradict the tables.
                (plots_dir / name).unlink(missing_ok=True)
                print(f"report: {name}: not enough cells for this plot, left out", file=sys.stderr)
    try:
        plots_rel = plots_dir.resolve().relative_to(args.results.resolve().parent).as_posix()
    except ValueError:
        plots_rel = plots_dir.resolve().as_posix()
    generated = section(data, machine, argv, plots_rel, made)
    existing = args.results.read_text() if args.results.exists() else "# Benchmark results\n"
    args.results.write_text(splice(existing, generated))
    print(f"report: {len(data.cells)} cells, {len(made)} plots -> {args.results}, {plots_dir}")
    return 0
